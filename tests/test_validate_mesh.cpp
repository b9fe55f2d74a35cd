// validate_mesh (every error names the element, its file and line) and
// mesh_quality.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/mesh_quality.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "io_test_util.hpp"
#include "test_meshes.hpp"

using namespace edgefem;
using edgefem::test::data_file;
using edgefem::test::expect_mesh_error;

namespace {
Mesh bad(const std::string& name) { return read_tetgen(data_file("bad/" + name)); }
}  // namespace

TEST(validate_mesh, GoodMeshesPass) {
    Mesh small = read_tetgen(data_file("small1"));
    const Mesh before = small;
    const ValidationReport r = validate_mesh(small);
    EXPECT_EQ(r.flipped_tets, 0);
    EXPECT_EQ(r.unreferenced_vertices, 0);
    EXPECT_EQ(r.removed_vertices, 0);
    EXPECT_TRUE(r.warnings.empty());
    EXPECT_EQ(small.X, before.X);
    EXPECT_EQ(small.tets, before.tets);
    for (auto& [name, mesh] : test::test_meshes(60000)) {
        SCOPED_TRACE(name);
        EXPECT_NO_THROW(validate_mesh(mesh));
    }
}

TEST(validate_mesh, NoTets) {
    Mesh m = read_tetgen(data_file("small0"));
    m.tets.clear();
    expect_mesh_error([&] { validate_mesh(m); }, {"small0.ele", "no tets"});
    Mesh empty;
    expect_mesh_error([&] { validate_mesh(empty); }, {"no tets"});
}

TEST(validate_mesh, IndexOutOfRange) {
    Mesh m = read_tetgen(data_file("small0"));
    m.tets[6] = 99;
    expect_mesh_error([&] { validate_mesh(m); },
                      {"tet 1 at ", "small0.ele:3", "vertex index 99", "out of range"});
    Mesh box = make_box(1, 1, 1);
    box.tets[0] = -1;
    expect_mesh_error([&] { validate_mesh(box); }, {"tet 0", "vertex index -1"});
}

TEST(validate_mesh, NonFiniteCoordinate) {
    Mesh m = read_tetgen(data_file("small1"));
    m.X[3 * 4 + 1] = std::numeric_limits<double>::quiet_NaN();
    expect_mesh_error([&] { validate_mesh(m); },
                      {"vertex 4 (numbered 5 in the file) at ", "small1.node:10", "non-finite"});
}

TEST(validate_mesh, DegenerateTet) {
    Mesh m = bad("degenerate");
    expect_mesh_error([&] { validate_mesh(m); },
                      {"tet 2 at ", "degenerate.ele:4", "degenerate", "normalised volume"});
    // A tet that repeats a vertex is degenerate too.
    Mesh r = read_tetgen(data_file("small0"));
    r.tets[3] = r.tets[1];
    expect_mesh_error([&] { validate_mesh(r); }, {"tet 0 at ", "small0.ele:2", "twice"});
    // The tolerance is honoured: Kuhn tets have normalised volume 0.27.
    Mesh box = make_box(2, 2, 2);
    ValidationOptions strict;
    strict.degenerate_tolerance = 0.5;
    expect_mesh_error([&] { validate_mesh(box, strict); }, {"tet 0", "degenerate", "48 degenerate tets"});
    strict.degenerate_tolerance = 0.25;
    EXPECT_NO_THROW(validate_mesh(box, strict));
}

TEST(validate_mesh, DuplicateTet) {
    Mesh m = bad("duplicate");
    expect_mesh_error([&] { validate_mesh(m); },
                      {"tet 3 at ", "duplicate.ele:5", "duplicates tet 0 at ", "duplicate.ele:2"});
}

TEST(validate_mesh, InvertedTet) {
    Mesh m = bad("inverted");
    expect_mesh_error([&] { validate_mesh(m); },
                      {"1 of 3 tets are inverted", "tet 1 at ", "inverted.ele:3", "fix_orientation"});
    ValidationOptions fix;
    fix.fix_orientation = true;
    const ValidationReport r = validate_mesh(m, fix);
    EXPECT_EQ(r.flipped_tets, 1);
    EXPECT_EQ(std::vector<index_t>(m.tets.begin() + 4, m.tets.begin() + 8),
              (std::vector<index_t>{1, 2, 3, 4}));
    EXPECT_NO_THROW(validate_mesh(m));

    // Every tet of a box flipped: all are fixed consistently.
    Mesh box = make_box(3, 2, 2);
    for (index_t t = 0; t < box.num_tets(); ++t) std::swap(box.tets[4 * t], box.tets[4 * t + 1]);
    expect_mesh_error([&] { validate_mesh(box); }, {"72 of 72 tets are inverted", "tet 0"});
    EXPECT_EQ(validate_mesh(box, fix).flipped_tets, 72);
    EXPECT_GT(mesh_quality(box).min_volume, 0);
}

TEST(validate_mesh, UnreferencedVertex) {
    Mesh m = bad("unreferenced");
    const ValidationReport r = validate_mesh(m);
    EXPECT_EQ(r.unreferenced_vertices, 1);
    EXPECT_EQ(r.removed_vertices, 0);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("1 of 7 vertices"), std::string::npos) << r.warnings[0];
    EXPECT_NE(r.warnings[0].find("vertex 5 at "), std::string::npos) << r.warnings[0];
    EXPECT_NE(r.warnings[0].find("unreferenced.node:7"), std::string::npos) << r.warnings[0];
    EXPECT_EQ(m.num_vertices(), 7);

    ValidationOptions compact;
    compact.compact_unreferenced = true;
    const ValidationReport c = validate_mesh(m, compact);
    EXPECT_EQ(c.removed_vertices, 1);
    EXPECT_EQ(m.num_vertices(), 6);
    EXPECT_EQ(m.tets, (std::vector<index_t>{0, 1, 2, 3, 1, 2, 3, 4, 0, 2, 1, 5}));
    EXPECT_EQ(m.X[15], 0.05);
    EXPECT_EQ(m.X[17], -0.1);
    EXPECT_EQ(m.source.vertex_line, (std::vector<std::int64_t>{2, 3, 4, 5, 6, 8}));
    EXPECT_EQ(m.source.vertex_id, (std::vector<std::int64_t>{0, 1, 2, 3, 4, 6}));
    EXPECT_NE(m.describe_vertex(5).find("numbered 6 in the file"), std::string::npos);
    EXPECT_EQ(validate_mesh(m).unreferenced_vertices, 0);
}

TEST(validate_mesh_quality, Box) {
    const Mesh box = make_box(10, 5, 4);
    const MeshQuality q = mesh_quality(box);
    EXPECT_NEAR(q.min_volume, 1e-6 / 6, 1e-18);
    EXPECT_NEAR(q.max_volume, 1e-6 / 6, 1e-18);
    EXPECT_NEAR(q.total_volume, 2e-4, 1e-15);
    EXPECT_NEAR(q.min_dihedral_deg, 45.0, 1e-9);
    EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-9);
    EXPECT_NEAR(q.bbox_min[0], -0.05, 1e-15);
    EXPECT_NEAR(q.bbox_max[1], 0.025, 1e-15);
    EXPECT_NEAR(q.bbox_max[2], 0.02, 1e-15);
}

TEST(validate_mesh_quality, RegularTet) {
    Mesh reg;
    reg.X = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
    reg.tets = {0, 1, 2, 3};
    const MeshQuality q = mesh_quality(reg);
    const double expected = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;  // 70.53 degrees
    EXPECT_NEAR(q.min_dihedral_deg, expected, 1e-9);
    EXPECT_NEAR(q.max_dihedral_deg, expected, 1e-9);
    EXPECT_NEAR(std::fabs(q.total_volume), 8.0 / 3.0, 1e-12);
}

TEST(validate_mesh_quality, SharedMeshesMatchReadme) {
    // Dihedral angles and volumes from ../shared/meshes/README.md.
    struct Row {
        const char* name;
        double min_dih, max_dih, total;
    };
    int found = 0;
    for (const Row& row : {Row{"spot-2k", 12.11, 161.57, 1.5193e-4},
                           Row{"bunny-4k", 10.79, 161.31, 1.9868e-4},
                           Row{"armadillo-7k", 11.19, 162.92, 6.7466e-5}}) {
        const std::string prefix = test::shared_mesh_prefix(row.name);
        if (prefix.empty()) continue;
        ++found;
        const MeshQuality s = mesh_quality(read_tetgen(prefix));
        EXPECT_NEAR(s.min_dihedral_deg, row.min_dih, 0.006) << row.name;
        EXPECT_NEAR(s.max_dihedral_deg, row.max_dih, 0.006) << row.name;
        EXPECT_NEAR(s.total_volume, row.total, 1e-4 * row.total) << row.name;
        EXPECT_NEAR(std::max(s.bbox_max[0] - s.bbox_min[0],
                             std::max(s.bbox_max[1] - s.bbox_min[1], s.bbox_max[2] - s.bbox_min[2])),
                    0.1, 1e-9)
            << row.name;
    }
    if (found == 0) GTEST_SKIP() << "shared meshes not found under " << test::shared_mesh_dir();
}

// The 1M-tet bunny validates well under a second (Release build).
// The largest shared mesh reads and validates clean (its speed is measured
// in bench_topology's validate/bunny-1m, not here).
TEST(validate_mesh, MillionTetMeshValidates) {
    const std::string prefix = test::shared_mesh_prefix("bunny-1m");
    if (prefix.empty()) GTEST_SKIP() << "bunny-1m not found under " << test::shared_mesh_dir();
    Mesh m = read_tetgen(prefix);
    const ValidationReport r = validate_mesh(m);
    EXPECT_EQ(m.num_tets(), 1003465);
    EXPECT_EQ(r.unreferenced_vertices, 0);
}
