// Mesh readers: the same small mesh in every format, the shared meshes in
// TetGen and Gmsh form, malformed files, and a truncation / byte-flip fuzz.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "io_test_util.hpp"
#include "test_meshes.hpp"

using namespace edgefem;
using edgefem::test::data_file;
using edgefem::test::expect_mesh_error;

namespace {

// The mesh every file in tests/data/small* holds.
const std::vector<double> kX = {0,   0,   0,   0.1, 0,    0,   0, 0.1, 0,
                                0,   0,   0.1, 0.1, 0.1,  0.1, 0.05, 0.05, -0.1};
const std::vector<index_t> kTets = {0, 1, 2, 3, 1, 2, 3, 4, 0, 2, 1, 5};
const std::vector<int> kRegion = {1, 2, 1};

void expect_small_mesh(const Mesh& m, bool with_region) {
    EXPECT_EQ(m.X, kX);
    EXPECT_EQ(m.tets, kTets);
    if (with_region) EXPECT_EQ(m.region, kRegion);
    else EXPECT_TRUE(m.region.empty());
    EXPECT_EQ(m.source.vertex_line.size(), 6u);
    EXPECT_EQ(m.source.vertex_id.size(), 6u);
    EXPECT_EQ(m.source.tet_line.size(), 3u);
    EXPECT_EQ(m.source.tet_id.size(), 3u);
}

// small.veg: the same mesh; its one *MATERIAL covers every tet (region 1).
void expect_small_vega(Mesh m) {
    EXPECT_EQ(m.region, (std::vector<int>{1, 1, 1}));
    m.region.clear();
    expect_small_mesh(m, false);
}

std::string replace_once(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' not found";
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

}  // namespace

TEST(read_mesh, AllFormatsGiveTheSameMesh) {
    expect_small_mesh(read_tetgen(data_file("small0")), false);
    expect_small_mesh(read_tetgen(data_file("small0.node")), false);
    expect_small_mesh(read_tetgen(data_file("small1.ele")), true);
    expect_small_mesh(read_gmsh(data_file("small22.msh")), true);
    expect_small_mesh(read_gmsh(data_file("small41.msh")), true);
    expect_small_mesh(read_medit(data_file("small.mesh")), true);
    expect_small_vega(read_vega(data_file("small.veg")));
    // Dispatch by extension and by TetGen prefix.
    expect_small_mesh(read_mesh(data_file("small0")), false);
    expect_small_mesh(read_mesh(data_file("small1.node")), true);
    expect_small_mesh(read_mesh(data_file("small22.msh")), true);
    expect_small_mesh(read_mesh(data_file("small41.msh")), true);
    expect_small_mesh(read_mesh(data_file("small.mesh")), true);
    expect_small_vega(read_mesh(data_file("small.veg")));
    expect_small_vega(read_mesh(data_file("small.veg"), MeshFormat::Vega));
}

TEST(read_mesh, TetGenSourceLinesAndIds) {
    const Mesh m = read_tetgen(data_file("small1"));
    EXPECT_EQ(m.source.vertex_file, data_file("small1.node"));
    EXPECT_EQ(m.source.tet_file, data_file("small1.ele"));
    EXPECT_EQ(m.source.vertex_line, (std::vector<std::int64_t>{4, 5, 8, 9, 10, 11}));
    EXPECT_EQ(m.source.vertex_id, (std::vector<std::int64_t>{1, 2, 3, 4, 5, 6}));
    EXPECT_EQ(m.source.tet_line, (std::vector<std::int64_t>{3, 4, 6}));
    EXPECT_EQ(m.source.tet_id, (std::vector<std::int64_t>{1, 2, 3}));
    const Mesh z = read_tetgen(data_file("small0"));
    EXPECT_EQ(z.source.vertex_id, (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(z.source.tet_line, (std::vector<std::int64_t>{2, 3, 4}));
    EXPECT_NE(m.describe_tet(2).find("small1.ele:6"), std::string::npos) << m.describe_tet(2);
}

TEST(read_mesh, GmshTagsLinesAndSkippedElements) {
    ReadReport report;
    const Mesh m = read_gmsh(data_file("small22.msh"), &report);
    EXPECT_EQ(m.source.vertex_id, (std::vector<std::int64_t>{10, 20, 30, 40, 55, 7}));
    EXPECT_EQ(m.source.vertex_line, (std::vector<std::int64_t>{11, 12, 13, 14, 15, 16}));
    EXPECT_EQ(m.source.tet_id, (std::vector<std::int64_t>{4, 6, 7}));
    EXPECT_EQ(m.source.tet_line, (std::vector<std::int64_t>{23, 25, 26}));
    EXPECT_EQ(report.skipped_elements, 4);
    EXPECT_EQ(report.skipped_summary, "1 x line (type 1), 2 x triangle (type 2), 1 x point (type 15)");

    ReadReport report41;
    const Mesh m41 = read_gmsh(data_file("small41.msh"), &report41);
    EXPECT_EQ(report41.skipped_elements, 2);
    EXPECT_EQ(report41.skipped_summary, "2 x triangle (type 2)");
    EXPECT_EQ(m41.source.vertex_id, (std::vector<std::int64_t>{101, 102, 103, 104, 105, 106}));
    EXPECT_EQ(m41.source.tet_id, (std::vector<std::int64_t>{2, 3, 4}));
}

TEST(read_mesh, Gmsh41RegionFallsBackToEntityTag) {
    edgefem::test::TempDir dir("read41");
    std::string text = edgefem::test::slurp(data_file("small41.msh"));
    const auto a = text.find("$Entities"), b = text.find("$EndEntities\n");
    text.erase(a, b + 13 - a);
    edgefem::test::spit(dir.file("noent.msh"), text);
    const Mesh m = read_gmsh(dir.file("noent.msh"));
    EXPECT_EQ(m.region, (std::vector<int>{1, 2, 3}));
    EXPECT_EQ(m.tets, kTets);
}

TEST(read_mesh, MeditSkipsOtherSections) {
    ReadReport report;
    const Mesh m = read_medit(data_file("small.mesh"), &report);
    EXPECT_EQ(report.skipped_elements, 3);  // 1 edge + 2 triangles; corners are not elements
    EXPECT_EQ(report.skipped_summary, "2 x Corners, 1 x Edges, 2 x triangles");
    EXPECT_EQ(m.source.vertex_id[5], 6);
    EXPECT_EQ(m.source.tet_line, (std::vector<std::int64_t>{27, 28, 29}));
}

TEST(read_mesh, TetGenTenNodeTetsKeepCorners) {
    edgefem::test::TempDir dir("read10");
    // small0 plus 6 extra (mid-edge) vertices; only the corners are kept.
    std::string node = "12 3 0 0\n" + edgefem::test::slurp(data_file("small0.node")).substr(8);
    for (int i = 6; i < 12; ++i) node += std::to_string(i) + " 1 1 " + std::to_string(i) + "\n";
    edgefem::test::spit(dir.file("ten.node"), node);
    edgefem::test::spit(dir.file("ten.ele"),
                        "3 10 1\n"
                        "0 0 1 2 3 6 7 8 9 10 11 1\n"
                        "1 1 2 3 4 6 7 8 9 10 11 2\n"
                        "2 0 2 1 5 6 7 8 9 10 11 1\n");
    ReadReport report;
    const Mesh m = read_tetgen(dir.file("ten"), &report);
    EXPECT_EQ(m.tets, kTets);
    EXPECT_EQ(m.region, kRegion);
    EXPECT_EQ(m.num_vertices(), 12);
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("10-node"), std::string::npos);
}

TEST(read_mesh, UpperCaseTetGenExtensions) {
    edgefem::test::TempDir dir("readcase");
    const std::string node = edgefem::test::slurp(data_file("small0.node"));
    const std::string ele = edgefem::test::slurp(data_file("small0.ele"));
    edgefem::test::spit(dir.file("UP.NODE"), node);
    edgefem::test::spit(dir.file("UP.ELE"), ele);
    // read_mesh detected these as TetGen, then looked for UP.NODE.node.
    expect_small_mesh(read_mesh(dir.file("UP.NODE")), false);
    expect_small_mesh(read_mesh(dir.file("UP.ELE")), false);
    expect_small_mesh(read_mesh(dir.file("UP")), false);
    const Mesh m = read_tetgen(dir.file("UP.ELE"));
    EXPECT_EQ(m.source.vertex_file, dir.file("UP.NODE"));
    EXPECT_EQ(m.source.tet_file, dir.file("UP.ELE"));
    // Mixed case: the partner in the other case when that is the one present.
    edgefem::test::spit(dir.file("mix.Node"), node);
    edgefem::test::spit(dir.file("mix.ele"), ele);
    expect_small_mesh(read_mesh(dir.file("mix.Node")), false);
    edgefem::test::spit(dir.file("lone.NODE"), node);
    expect_mesh_error([&] { read_mesh(dir.file("lone.NODE")); }, {"lone.ELE", "cannot open"});
}

TEST(read_mesh, QuadraticTetsKeepCornersInGmshAndMedit) {
    edgefem::test::TempDir dir("readp2");
    const std::string msh = edgefem::test::slurp(data_file("small22.msh"));
    // Gmsh type 11: the 4 corners, then 6 mid-edge nodes (here existing tags).
    std::string m10 = replace_once(msh, "4 4 2 1 100 10 20 30 40", "4 11 2 1 100 10 20 30 40 7 7 7 7 7 7");
    m10 = replace_once(m10, "6 4 2 2 100 20 30 40 55", "6 11 2 2 100 20 30 40 55 7 7 7 7 7 7");
    edgefem::test::spit(dir.file("t10.msh"), m10);
    ReadReport report;
    const Mesh g = read_gmsh(dir.file("t10.msh"), &report);
    EXPECT_EQ(g.tets, kTets);
    EXPECT_EQ(g.region, kRegion);
    EXPECT_EQ(report.skipped_elements, 4);
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("10-node"), std::string::npos);
    edgefem::test::spit(dir.file("undef10.msh"), replace_once(m10, "55 7 7 7 7 7 7", "55 7 7 7 7 7 99"));
    expect_mesh_error([&] { read_gmsh(dir.file("undef10.msh")); }, {"undef10.msh:25:", "node tag 99"});
    // MSH 4.1: a block of 10-node tets.
    const std::string msh41 = edgefem::test::slurp(data_file("small41.msh"));
    edgefem::test::spit(dir.file("t10_41.msh"),
                        replace_once(msh41, "3 1 4 1\n2 101 102 103 104\n", "3 1 11 1\n2 101 102 103 104 105 105 105 105 105 105\n"));
    EXPECT_EQ(read_gmsh(dir.file("t10_41.msh")).tets, kTets);

    // MEDIT TetrahedraP2: the same, 10 indices and a reference per line.
    const std::string medit = edgefem::test::slurp(data_file("small.mesh"));
    std::string p2 = replace_once(medit, "TETRAHEDRA\n3\n1 2 3 4 1\n2 3 4 5 2\n1 3 2 6 1\n",
                                  "TetrahedraP2\n3\n1 2 3 4 6 6 6 6 6 6 1\n2 3 4 5 1 1 1 1 1 1 2\n1 3 2 6 4 4 4 4 4 4 1\n");
    edgefem::test::spit(dir.file("p2.mesh"), p2);
    ReadReport mreport;
    const Mesh m = read_medit(dir.file("p2.mesh"), &mreport);
    EXPECT_EQ(m.tets, kTets);
    EXPECT_EQ(m.region, kRegion);
    ASSERT_EQ(mreport.warnings.size(), 1u);
    EXPECT_NE(mreport.warnings[0].find("TetrahedraP2"), std::string::npos);
    edgefem::test::spit(dir.file("p2range.mesh"), replace_once(p2, "2 3 4 5 1 1 1 1 1 1 2", "2 3 4 5 1 1 1 1 1 7 2"));
    expect_mesh_error([&] { read_medit(dir.file("p2range.mesh")); }, {"p2range.mesh:28:", "vertex index 7"});
}

// Simulating the tets of a mesh that also has hexahedra, prisms or pyramids
// would drop part of the body without a word: those are errors.
TEST(read_mesh_errors, OtherVolumeElements) {
    edgefem::test::TempDir dir("readvol");
    const std::string msh = edgefem::test::slurp(data_file("small22.msh"));
    auto p = dir.file("hex.msh");
    edgefem::test::spit(p, replace_once(msh, "5 2 2 7 1 20 30 55", "5 5 2 1 100 10 20 30 40 55 7 10 20"));
    expect_mesh_error([&] { read_mesh(p); },
                      {"hex.msh:24:", "mesh has 1 x hexahedron (type 5)", "simulates tets only", "convert the mesh to tets"});
    p = dir.file("mixed.msh");
    std::string mixed = replace_once(msh, "$Elements\n7\n", "$Elements\n9\n");
    mixed = replace_once(mixed, "$EndElements", "8 6 2 1 100 10 20 30 40 55 7\n9 7 2 1 100 10 20 30 40 55\n$EndElements");
    mixed = replace_once(mixed, "3 2 2 7 1 10 20 30", "3 17 2 7 1 10 20 30 10 20 30 10 20 30 10 20 30 10 20 30 10 20 30 10 20");
    edgefem::test::spit(p, mixed);
    expect_mesh_error([&] { read_mesh(p); },
                      {"mixed.msh:22:", "1 x prism (type 6), 1 x pyramid (type 7), 1 x 20-node hexahedron (type 17)"});
    p = dir.file("unknown.msh");
    edgefem::test::spit(p, replace_once(msh, "5 2 2 7 1 20 30 55", "5 200 2 7 1 20 30 55"));
    expect_mesh_error([&] { read_mesh(p); }, {"unknown.msh:24:", "element type 200 is unknown"});
    // MSH 4.1: the block's entity dimension says "volume" whatever the type.
    const std::string msh41 = edgefem::test::slurp(data_file("small41.msh"));
    p = dir.file("hex41.msh");
    edgefem::test::spit(p, replace_once(msh41, "2 1 2 2\n", "3 1 5 2\n"));
    expect_mesh_error([&] { read_mesh(p); }, {"hex41.msh:37:", "mesh has 2 x hexahedron (type 5)"});
    p = dir.file("odd41.msh");
    edgefem::test::spit(p, replace_once(msh41, "2 1 2 2\n", "3 1 300 2\n"));
    expect_mesh_error([&] { read_mesh(p); }, {"odd41.msh:37:", "2 x element (type 300)"});
    // MEDIT
    const std::string medit = edgefem::test::slurp(data_file("small.mesh"));
    p = dir.file("hex.mesh");
    edgefem::test::spit(p, replace_once(medit, "End", "Hexahedra\n1\n1 2 3 4 5 6 1 2 0\nPrisms 1\n1 2 3 4 5 6 0\nEnd"));
    expect_mesh_error([&] { read_mesh(p); },
                      {"hex.mesh:30:", "mesh has 1 x Hexahedra, 1 x Prisms", "convert the mesh to tets"});
}

TEST(read_mesh_errors, MissingAndUnknownFiles) {
    expect_mesh_error([] { read_tetgen(data_file("no_such_mesh")); },
                      {"no_such_mesh.node", "cannot open"});
    expect_mesh_error([] { read_gmsh(data_file("no_such_mesh.msh")); }, {"no_such_mesh.msh"});
    expect_mesh_error([] { read_mesh(data_file("small.stl")); }, {"small.stl", "mesh format"});
    expect_mesh_error([] { read_mesh(data_file("x.meshb")); }, {"binary MEDIT"});
    expect_mesh_error([] { read_medit(test::test_data_dir()); }, {"is a directory, not a mesh file"});
    // A device is never loaded: /dev/zero would be read until memory ran out.
    expect_mesh_error([] { read_gmsh("/dev/zero"); }, {"/dev/zero: not a regular file"});
    expect_mesh_error([] { read_tetgen("/dev/null"); }, {"/dev/null.node", "cannot open"});
}

TEST(read_mesh_errors, HandWrittenBadFiles) {
    const auto bad = [](const std::string& name) { return data_file("bad/" + name); };
    expect_mesh_error([&] { read_tetgen(bad("truncated")); }, {"truncated.ele:1:", "truncated"});
    expect_mesh_error([&] { read_tetgen(bad("bad_header")); },
                      {"bad_header.node:1:", "'six'", "vertex count"});
    expect_mesh_error([&] { read_gmsh(bad("bad_header.msh")); },
                      {"bad_header.msh:2:", "unsupported MSH version '3.0'"});
    expect_mesh_error([&] { read_tetgen(bad("out_of_range")); },
                      {"out_of_range.ele:3:", "tet 1", "vertex index 6", "out of range", "0..5"});
    expect_mesh_error([&] { read_tetgen(bad("nan")); },
                      {"nan.node:4:", "vertex 2", "non-finite", "nan"});
    expect_mesh_error([&] { read_tetgen(bad("negative_count")); },
                      {"negative_count.node:1:", "negative vertex count -6"});
    expect_mesh_error([&] { read_tetgen(bad("huge_count")); },
                      {"huge_count.ele:1:", "999999999999", "exceeds"});
    expect_mesh_error([&] { read_gmsh(bad("huge_count.msh")); },
                      {"huge_count.msh:5:", "2000000000", "more than the rest of the file"});
    expect_mesh_error([&] { read_gmsh(bad("binary.msh")); },
                      {"binary.msh:2:", "binary MSH is not supported"});
    expect_mesh_error([&] { read_mesh(bad("garbage.msh")); }, {"garbage.msh:1:", "not a Gmsh"});
    expect_mesh_error([&] { read_medit(bad("empty.mesh")); }, {"empty.mesh", "file is empty"});
    expect_mesh_error([&] { read_tetgen(bad("empty")); }, {"empty.node", "file is empty"});
    expect_mesh_error([&] { read_gmsh(bad("duplicate_node.msh")); },
                      {"duplicate_node.msh:9:", "duplicate node tag 2", "line 7"});
    expect_mesh_error([&] { read_tetgen(bad("duplicate_id")); },
                      {"duplicate_id.node:4:", "duplicate vertex number 1", "line 3"});
    expect_mesh_error([&] { read_vega(bad("cubic.veg")); },
                      {"cubic.veg:8:", "CUBIC", "not supported"});
    expect_mesh_error([&] { read_vega(bad("include.veg")); },
                      {"include.veg:1:", "*INCLUDE is not supported"});
}

// Variants of the good files, each broken in one way.
TEST(read_mesh_errors, EditedVariants) {
    edgefem::test::TempDir dir("readbad");
    const std::string msh = edgefem::test::slurp(data_file("small22.msh"));
    const std::string msh41 = edgefem::test::slurp(data_file("small41.msh"));
    const std::string medit = edgefem::test::slurp(data_file("small.mesh"));
    const std::string veg = edgefem::test::slurp(data_file("small.veg"));
    const std::string node = edgefem::test::slurp(data_file("small0.node"));
    const std::string ele = edgefem::test::slurp(data_file("small0.ele"));
    const auto write = [&](const std::string& name, const std::string& text) {
        edgefem::test::spit(dir.file(name), text);
        return dir.file(name);
    };
    const auto tetgen = [&](const std::string& name, const std::string& n, const std::string& e) {
        write(name + ".node", n);
        write(name + ".ele", e);
        return dir.file(name);
    };

    // Gmsh
    auto p = write("undef.msh", replace_once(msh, "7 4 2 1 100 10 30 20 7", "7 4 2 1 100 10 30 20 99"));
    expect_mesh_error([&] { read_gmsh(p); },
                      {"undef.msh:26:", "tet 2 (numbered 7 in the file)", "node tag 99"});
    p = write("word.msh", replace_once(msh, "40 0 0 0.1", "40 0 zero 0.1"));
    expect_mesh_error([&] { read_gmsh(p); }, {"word.msh:14:", "'zero'", "y coordinate"});
    p = write("inf.msh", replace_once(msh, "40 0 0 0.1", "40 0 0 -inf"));
    expect_mesh_error([&] { read_gmsh(p); }, {"inf.msh:14:", "vertex 3 (numbered 40 in the file)", "non-finite", "inf"});
    p = write("short.msh", msh.substr(0, msh.find("30 0 0.1 0")));
    expect_mesh_error([&] { read_gmsh(p); }, {"short.msh:10:", "truncated"});
    p = write("count.msh", replace_once(msh, "$Elements\n7\n", "$Elements\n6\n"));
    expect_mesh_error([&] { read_gmsh(p); }, {"count.msh:26:", "$EndElements"});
    p = write("noend.msh", replace_once(msh, "$EndComments\n", ""));
    expect_mesh_error([&] { read_gmsh(p); }, {"noend.msh:28:", "$EndComments", "truncated"});
    p = write("tags.msh", replace_once(msh, "4 4 2 1 100 10 20 30 40", "4 4 9 1 100 10 20 30 40"));
    expect_mesh_error([&] { read_gmsh(p); }, {"tags.msh:23:", "number of tags 9"});
    p = write("v40.msh", replace_once(msh, "2.2 0 8", "4.0 0 8"));
    expect_mesh_error([&] { read_gmsh(p); }, {"v40.msh:2:", "unsupported MSH version '4.0'"});
    p = write("blocks.msh", replace_once(msh41, "3 2 0 2\n", "3 2 0 3\n"));
    expect_mesh_error([&] { read_gmsh(p); }, {"blocks.msh:", "more nodes than the header"});
    p = write("neg41.msh", replace_once(msh41, "3 1 4 1\n", "3 1 4 -1\n"));
    expect_mesh_error([&] { read_gmsh(p); }, {"neg41.msh:", "negative element count -1"});

    // MEDIT
    p = write("range.mesh", replace_once(medit, "2 3 4 5 2", "2 3 4 7 2"));
    expect_mesh_error([&] { read_medit(p); },
                      {"range.mesh:28:", "tet 1 (numbered 2 in the file)", "vertex index 7", "1..6"});
    p = write("dim.mesh", replace_once(medit, "Dimension\n3", "Dimension\n2"));
    expect_mesh_error([&] { read_medit(p); }, {"dim.mesh:4:", "dimension 2"});
    p = write("neg.mesh", replace_once(medit, "Vertices\n6", "Vertices\n-6"));
    expect_mesh_error([&] { read_medit(p); }, {"neg.mesh:7:", "negative vertex count"});
    p = write("notmedit.mesh", "Hello world\n");
    expect_mesh_error([&] { read_medit(p); }, {"notmedit.mesh:1:", "MeshVersionFormatted"});
    p = write("trunc.mesh", medit.substr(0, medit.find("TETRAHEDRA") + 13));
    expect_mesh_error([&] { read_medit(p); }, {"trunc.mesh:", "truncated"});
    // A skipped section's count too large or too small: the message names it.
    p = write("skipbig.mesh", replace_once(medit, "triangles\n2\n", "triangles\n5\n"));
    expect_mesh_error([&] { read_medit(p); },
                      {"skipbig.mesh:25:", "while reading section triangles (5 items)", "found keyword 'TETRAHEDRA'"});
    p = write("skipsmall.mesh", replace_once(medit, "triangles\n2\n", "triangles\n1\n"));
    expect_mesh_error([&] { read_medit(p); },
                      {"skipsmall.mesh:24:", "expected a section keyword, got '2'", "section triangles"});

    // Vega
    p = write("range.veg", replace_once(veg, "2 2 3 4 5", "2 2 3 4 0"));
    expect_mesh_error([&] { read_vega(p); }, {"range.veg:16:", "tet 1 (numbered 2 in the file)", "vertex index 0"});
    p = write("nan.veg", replace_once(veg, "5 0.1 0.1 0.1", "5 0.1 NaN 0.1"));
    expect_mesh_error([&] { read_vega(p); }, {"nan.veg:8:", "vertex 4 (numbered 5 in the file)", "non-finite"});
    p = write("extra.veg", replace_once(veg, "6 0.05 0.05 -0.1\n", "6 0.05 0.05 -0.1\n7 1 1 1\n"));
    expect_mesh_error([&] { read_vega(p); }, {"extra.veg:10:", "more lines than the section's count"});
    // found by the fuzzer: a constants line of separators only (read f[0] of nothing)
    p = write("blank-material.veg", replace_once(veg, "ENU, 1000, 10000000, 0.45", " ,"));
    expect_mesh_error([&] { read_vega(p); }, {"blank-material.veg:20:", "expected 'ENU, density, E, nu', got no values"});
    p = write("count.veg", replace_once(veg, "3 4 0\n", "3 8 0\n"));
    expect_mesh_error([&] { read_vega(p); }, {"count.veg:14:", "nodes per element must be 4"});

    // TetGen
    p = tetgen("extra", node + "6 1 1 1\n", ele);
    expect_mesh_error([&] { read_tetgen(p); }, {"extra.node:8:", "more vertex lines"});
    p = tetgen("gap", replace_once(node, "3 0 0 0.1", "4 0 0 0.1"), ele);
    expect_mesh_error([&] { read_tetgen(p); }, {"gap.node:5:", "consecutively", "expected 3, got 4"});
    p = tetgen("missing", replace_once(node, "3 0 0 0.1", "3 0 0"), ele);
    expect_mesh_error([&] { read_tetgen(p); }, {"missing.node:5:", "missing z coordinate"});
    // In a file this small the byte-count check used to blame the count.
    p = tetgen("tight", "5 3 0 0\n1 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n", "1 4\n1 1 2 3 4\n");
    expect_mesh_error([&] { read_tetgen(p); }, {"tight.node:2:", "missing z coordinate"});
    p = tetgen("tightattr", "2 3 1 0\n1 0 0 0\n2 1 0 0 5\n", "1 4\n1 1 2 3 4\n");
    expect_mesh_error([&] { read_tetgen(p); }, {"tightattr.node:2:", "missing vertex attribute"});
    // A count the remaining lines cannot hold is still blamed at once.
    p = tetgen("count", "7 3 0 0\n1 0 0 0\n2 1 0 0\n", "1 4\n1 1 2 3 4\n");
    expect_mesh_error([&] { read_tetgen(p); }, {"count.node:1:", "vertex count 7 is more than the rest of the file"});
    p = tetgen("attr", node, "3 4 1\n0 0 1 2 3   # no attribute here\n1 1 2 3 4 2\n2 0 2 1 5 1\n");
    expect_mesh_error([&] { read_tetgen(p); }, {"attr.ele:2:", "missing tet attribute"});
    p = tetgen("dim", replace_once(node, "6 3 0 0", "6 2 0 0"), ele);
    expect_mesh_error([&] { read_tetgen(p); }, {"dim.node:1:", "dimension must be 3"});
    p = tetgen("npt", node, replace_once(ele, "3 4 0", "3 6 0"));
    expect_mesh_error([&] { read_tetgen(p); }, {"npt.ele:1:", "nodes per tet must be 4 or 10"});
    p = tetgen("int", node, replace_once(ele, "1 1 2 3 4", "1 1 2 3.5 4"));
    expect_mesh_error([&] { read_tetgen(p); }, {"int.ele:3:", "expected an integer", "'3.5'"});
    p = tetgen("big", node, replace_once(ele, "1 1 2 3 4", "1 1 2 99999999999999999999 4"));
    expect_mesh_error([&] { read_tetgen(p); }, {"big.ele:3:", "out of the 64-bit integer range"});
    p = tetgen("base", replace_once(node, "0 0 0 0\n1 0.1", "7 0 0 0\n1 0.1"), ele);
    expect_mesh_error([&] { read_tetgen(p); }, {"base.node:2:", "numbered 0 or 1, got 7"});
    // 1-based .node with 0-based indices in the .ele: index 0 is out of range.
    std::string node1 = "6 3 0 0\n";
    for (int i = 0; i < 6; ++i)
        node1 += std::to_string(i + 1) + " " + std::to_string(kX[3 * i]) + " " +
                 std::to_string(kX[3 * i + 1]) + " " + std::to_string(kX[3 * i + 2]) + "\n";
    p = tetgen("base1", node1, ele);
    expect_mesh_error([&] { read_tetgen(p); }, {"base1.ele:2:", "tet 0", "vertex index 0", "1..6"});
}

TEST(read_mesh_errors, MessagesQuoteTheFilesVertexNumbers) {
    edgefem::test::TempDir dir("readdup");
    const std::string node = edgefem::test::slurp(data_file("small1.node"));
    edgefem::test::spit(dir.file("dup.node"), node);
    edgefem::test::spit(dir.file("dup.ele"), "4 4\n1 1 2 3 4\n2 2 3 4 5\n3 1 3 2 6\n4 2 1 4 3\n");
    Mesh m = read_tetgen(dir.file("dup"));
    // 1-based file: the vertices are quoted 1..6, not 0..5.
    expect_mesh_error([&] { validate_mesh(m); }, {"duplicates tet 0", "(same vertices 2 1 4 3)"});
    edgefem::test::spit(dir.file("twice.node"), node);
    edgefem::test::spit(dir.file("twice.ele"), "1 4\n1 1 2 6 6\n");
    Mesh t = read_tetgen(dir.file("twice"));
    expect_mesh_error([&] { validate_mesh(t); }, {"uses vertex 6 twice"});
}

TEST(read_mesh, SharedMeshesTetGenAndGmshAgree) {
    int found = 0;
    for (const char* name : {"box-1200", "spot-2k", "bunny-4k", "armadillo-7k"}) {
        const std::string prefix = test::shared_mesh_prefix(name);
        if (prefix.empty()) continue;
        ++found;
        SCOPED_TRACE(name);
        const Mesh a = read_tetgen(prefix);
        ReadReport report;
        const Mesh b = read_gmsh(prefix + ".msh", &report);
        EXPECT_EQ(a.X, b.X);
        EXPECT_EQ(a.tets, b.tets);
        EXPECT_EQ(report.skipped_elements, 0);
        EXPECT_TRUE(a.region.empty());
        EXPECT_EQ(b.region, std::vector<int>(b.num_tets(), 1));
        const auto& table = test::shared_mesh_table();
        const auto info = std::find_if(table.begin(), table.end(),
                                       [&](const auto& i) { return std::string(i.name) == name; });
        ASSERT_NE(info, table.end());
        EXPECT_EQ(a.num_vertices(), info->vertices);
        EXPECT_EQ(a.num_tets(), info->tets);
        Mesh c = a;
        const ValidationReport v = validate_mesh(c);
        EXPECT_EQ(v.unreferenced_vertices, 0);
        EXPECT_EQ(v.flipped_tets, 0);
    }
    if (found == 0)
        GTEST_SKIP() << "shared meshes not found under " << test::shared_mesh_dir();
}

TEST(read_mesh, SharedMeshCountsMatchTable) {
    int found = 0;
    for (const auto& info : test::shared_mesh_table()) {
        if (info.tets > 300000) continue;  // the 1M mesh is read in test_validate_mesh
        const std::string prefix = test::shared_mesh_prefix(info.name);
        if (prefix.empty()) continue;
        ++found;
        const Mesh m = read_mesh(prefix + ".node");
        EXPECT_EQ(m.num_vertices(), info.vertices) << info.name;
        EXPECT_EQ(m.num_tets(), info.tets) << info.name;
    }
    if (found == 0)
        GTEST_SKIP() << "shared meshes not found under " << test::shared_mesh_dir();
}

// Every truncation and many random byte edits of the good files must either
// read or throw edgefem::Error: never crash, hang or throw anything else.
TEST(read_mesh_fuzz, TruncationsAndByteFlips) {
    edgefem::test::TempDir dir("fuzz");
    struct Case {
        std::string name;   // file to damage (written into dir)
        std::string other;  // TetGen partner file copied intact, or ""
        Mesh (*read)(const std::string&, ReadReport*);
    };
    const std::vector<Case> cases = {
        {"small22.msh", "", read_gmsh},       {"small41.msh", "", read_gmsh},
        {"small.mesh", "", read_medit},       {"small.veg", "", read_vega},
        {"small1.node", "small1.ele", read_tetgen}, {"small1.ele", "small1.node", read_tetgen},
    };
    std::mt19937 rng(20240611);
    static const char kAlphabet[] = "0123456789-+.eE \n\t#$*naifNAI\r\0\xff";
    const std::string alphabet(kAlphabet, sizeof kAlphabet - 1);
    int reads = 0, errors = 0;
    const auto attempt = [&](const Case& c, const std::string& text) {
        // Unlink first: rewriting in place makes ext4 flush on every close.
        std::filesystem::remove(dir.file(c.name));
        edgefem::test::spit(dir.file(c.name), text);
        try {
            ReadReport report;
            Mesh m = c.read(dir.file(c.name), &report);
            ++reads;
            try {
                validate_mesh(m, {});
            } catch (const edgefem::Error&) {
            }
        } catch (const edgefem::Error&) {
            ++errors;
        } catch (const std::exception& e) {
            ADD_FAILURE() << c.name << ": non-edgefem exception " << e.what() << " for input:\n"
                          << text;
        }
    };
    for (const Case& c : cases) {
        const std::string good = edgefem::test::slurp(data_file(c.name));
        ASSERT_FALSE(good.empty()) << c.name;
        if (!c.other.empty())
            edgefem::test::spit(dir.file(c.other), edgefem::test::slurp(data_file(c.other)));
        for (std::size_t n = 0; n <= good.size(); ++n) attempt(c, good.substr(0, n));
        for (int trial = 0; trial < 1500; ++trial) {
            std::string text = good;
            const int flips = 1 + static_cast<int>(rng() % 3);
            for (int f = 0; f < flips; ++f) {
                const std::size_t at = rng() % text.size();
                text[at] = (rng() % 2) ? alphabet[rng() % alphabet.size()]
                                       : static_cast<char>(rng() % 256);
            }
            attempt(c, text);
        }
    }
    EXPECT_GT(reads, 0);
    EXPECT_GT(errors, 0);
}

// Vega *MATERIAL / *SET / *REGION: each material becomes a region (the
// i-th *MATERIAL is region i) and ReadReport::materials carries its
// constants, so a two-material .veg is not simulated with one default.
TEST(read_mesh, VegaMaterialsBecomeRegions) {
    edgefem::test::TempDir dir("vegamat");
    ReadReport report;
    const Mesh one = read_vega(data_file("small.veg"), &report);
    EXPECT_EQ(one.region, (std::vector<int>{1, 1, 1}));
    ASSERT_EQ(report.materials.size(), 1u);
    EXPECT_EQ(report.materials.at(1).young, 1e7);
    EXPECT_EQ(report.materials.at(1).poisson, 0.45);
    EXPECT_EQ(report.materials.at(1).density, 1000);
    EXPECT_EQ(report.material_names.at(1), "defaultMaterial");

    const std::string veg = edgefem::test::slurp(data_file("small.veg"));
    const std::string two_text = replace_once(veg, "*SET allElements\n1, 2, 3,\n\n*REGION\nallElements, defaultMaterial",
                                              "*MATERIAL steel\nENU, 7800, 2e11, 0.3\n*SET soft\n1,\n3\n*SET hard\n2\n"
                                              "*REGION\nsoft, defaultMaterial\nhard, steel");
    edgefem::test::spit(dir.file("two.veg"), two_text);
    ReadReport r2;
    const Mesh two = read_vega(dir.file("two.veg"), &r2);
    EXPECT_EQ(two.region, (std::vector<int>{1, 2, 1}));
    ASSERT_EQ(r2.materials.size(), 2u);
    EXPECT_EQ(r2.materials.at(1).young, 1e7);
    EXPECT_EQ(r2.materials.at(2).young, 2e11);
    EXPECT_EQ(r2.materials.at(2).density, 7800);

    // Errors name the file, the line and the thing.
    const auto write = [&](const std::string& name, const std::string& text) {
        edgefem::test::spit(dir.file(name), text);
        return dir.file(name);
    };
    auto p = write("badtype.veg", replace_once(veg, "ENU, 1000, 10000000, 0.45", "MOONEYRIVLIN, 1000, 1, 2, 3"));
    expect_mesh_error([&] { read_vega(p); }, {"badtype.veg:20:", "MOONEYRIVLIN", "only ENU"});
    p = write("badnu.veg", replace_once(veg, "ENU, 1000, 10000000, 0.45", "ENU, 1000, 10000000, 0.7"));
    expect_mesh_error([&] { read_vega(p); }, {"badnu.veg:20:", "defaultMaterial", "oisson"});
    p = write("noset.veg", replace_once(veg, "allElements, defaultMaterial", "nothere, defaultMaterial"));
    expect_mesh_error([&] { read_vega(p); }, {"noset.veg:26:", "set 'nothere'"});
    p = write("nomat.veg", replace_once(veg, "allElements, defaultMaterial", "allElements, wood"));
    expect_mesh_error([&] { read_vega(p); }, {"nomat.veg:26:", "material 'wood'"});
    p = write("setrange.veg", replace_once(veg, "1, 2, 3,", "1, 2, 9"));
    expect_mesh_error([&] { read_vega(p); }, {"setrange.veg:23:", "element 9", "1..3"});
    p = write("twice.veg", replace_once(two_text, "2\n*REGION", "2, 3\n*REGION"));
    expect_mesh_error([&] { read_vega(p); }, {"twice.veg:", "tet 2 (numbered 3 in the file)", "two regions"});
    // A region that leaves tets without a material is said, not silent.
    ReadReport r3;
    p = write("partial.veg", replace_once(two_text, "hard, steel", ""));
    const Mesh partial = read_vega(p, &r3);
    EXPECT_EQ(partial.region, (std::vector<int>{1, 0, 1}));
    ASSERT_FALSE(r3.warnings.empty());
    EXPECT_NE(r3.warnings[0].find("1 of 3 tets"), std::string::npos) << r3.warnings[0];
    // Sections edgefem does not read are a warning naming them.
    ReadReport r4;
    p = write("other.veg", veg + "\n*FIXEDVERTICES\n1, 2\n");
    read_vega(p, &r4);
    ASSERT_EQ(r4.warnings.size(), 1u);
    EXPECT_NE(r4.warnings[0].find("*FIXEDVERTICES"), std::string::npos) << r4.warnings[0];
}

// Cubic (20-node) and higher Gmsh tets keep their corners, as quadratic ones
// do; they used to be refused as "not tets".
TEST(read_mesh, GmshCubicTetsKeepCorners) {
    edgefem::test::TempDir dir("readp3");
    const std::string msh = edgefem::test::slurp(data_file("small22.msh"));
    const std::string extra16 = " 7 7 7 7 7 7 7 7 7 7 7 7 7 7 7 7";
    std::string m20 = replace_once(msh, "4 4 2 1 100 10 20 30 40", "4 29 2 1 100 10 20 30 40" + extra16);
    m20 = replace_once(m20, "6 4 2 2 100 20 30 40 55", "6 29 2 2 100 20 30 40 55" + extra16);
    edgefem::test::spit(dir.file("t20.msh"), m20);
    ReadReport report;
    const Mesh g = read_gmsh(dir.file("t20.msh"), &report);
    EXPECT_EQ(g.tets, kTets);
    EXPECT_EQ(g.region, kRegion);
    EXPECT_TRUE(report.high_order_tets);
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("2 x 20-node"), std::string::npos) << report.warnings[0];
    // A missing node of a cubic tet is still an error naming the line.
    edgefem::test::spit(dir.file("short20.msh"), replace_once(m20, "55" + extra16, "55 7 7"));
    expect_mesh_error([&] { read_gmsh(dir.file("short20.msh")); }, {"short20.msh:", "tet node tag"});
}

// A region is an integer: -2.7 used to become region -3 silently.
TEST(read_mesh_errors, TetGenNonIntegerAttribute) {
    edgefem::test::TempDir dir("readattr");
    const std::string node = edgefem::test::slurp(data_file("small1.node"));
    const std::string ele = edgefem::test::slurp(data_file("small1.ele"));
    edgefem::test::spit(dir.file("attr.node"), node);
    edgefem::test::spit(dir.file("attr.ele"), replace_once(ele, "1  1 2 3 4   1.0  9.75", "1  1 2 3 4   -2.7  9.75"));
    expect_mesh_error([&] { read_tetgen(dir.file("attr")); }, {"attr.ele:3:", "region attribute -2.7", "not an integer"});
    // 2.0 is the integer 2; the second attribute is not a region and may be anything.
    edgefem::test::spit(dir.file("attr.ele"), replace_once(ele, "1  1 2 3 4   1.0  9.75", "1  1 2 3 4   2.0  9.75"));
    EXPECT_EQ(read_tetgen(dir.file("attr")).region[0], 2);
}

// A header that declares far more items than the file holds fails at the
// first short line, before memory is sized from the count: the readers grow
// with what the file holds (they used to resize to the declared count,
// 20x the file's size in resident memory).
TEST(read_mesh_errors, HugeCountBackedByShortLinesStaysSmall) {
    edgefem::test::TempDir dir("readhuge");
    const int n = 2000000;
    std::string lines;
    lines.reserve(2 * static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) lines += "1\n";
    edgefem::test::spit(dir.file("h.node"), std::to_string(n) + " 3 0 0\n" + lines);
    edgefem::test::spit(dir.file("h.ele"), "1 4 0\n1 1 2 3 4\n");
    edgefem::test::spit(dir.file("h.veg"), "*VERTICES\n" + std::to_string(n) + " 3 0 0\n" + lines);
    edgefem::test::spit(dir.file("h.mesh"), "MeshVersionFormatted 2\nDimension 3\nVertices\n" + std::to_string(n) + "\n" + lines);
    lines.clear();
    lines.shrink_to_fit();
    const long before = edgefem::test::peak_rss_kb();
    expect_mesh_error([&] { read_tetgen(dir.file("h.node")); }, {"h.node:2:", "missing x coordinate"});
    expect_mesh_error([&] { read_vega(dir.file("h.veg")); }, {"h.veg:3:", "missing x coordinate"});
    expect_mesh_error([&] { read_medit(dir.file("h.mesh")); }, {"h.mesh:5:", "missing y coordinate"});
    const long grown = edgefem::test::peak_rss_kb() - before;
    // The file itself (4 MB) is loaded; 2 million vertices would be 80 MB.
    EXPECT_LT(grown, 30 * 1024) << "peak RSS grew by " << grown << " kB";
}
