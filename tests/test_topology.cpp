// Topology: counts against ../shared/meshes/README.md and structural
// properties that any correct edge/TSEP construction must have.
#include <gtest/gtest.h>

#include <set>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/topology.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {

// Unique triangles counted independently with a std::set.
long count_triangles(const Mesh& mesh) {
    std::set<std::array<index_t, 3>> tris;
    for (index_t t = 0; t < mesh.num_tets(); ++t)
        for (int skip = 0; skip < 4; ++skip) {
            std::array<index_t, 3> f;
            int n = 0;
            for (int k = 0; k < 4; ++k)
                if (k != skip) f[n++] = mesh.tets[4 * t + k];
            std::sort(f.begin(), f.end());
            tris.insert(f);
        }
    return static_cast<long>(tris.size());
}

void check_structure(const Mesh& mesh, const Topology& topo) {
    // Edges: oriented, sorted, unique.
    for (index_t e = 0; e < topo.num_edges(); ++e) {
        ASSERT_LT(topo.edges[e][0], topo.edges[e][1]);
        if (e > 0) {
            ASSERT_LT(topo.edges[e - 1], topo.edges[e]);
        }
    }
    // tet_edges point at the right vertex pairs.
    for (index_t t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 6; ++k) {
            const index_t a = mesh.tets[4 * t + kTetEdge[k][0]], b = mesh.tets[4 * t + kTetEdge[k][1]];
            const auto& e = topo.edges[topo.tet_edges[t][k]];
            ASSERT_EQ(e[0], std::min(a, b));
            ASSERT_EQ(e[1], std::max(a, b));
        }
    // TSEPs: sorted unique pairs of distinct edges; opposite iff no shared vertex.
    for (index_t p = 0; p < topo.num_tseps(); ++p) {
        const auto& P = topo.tseps[p];
        ASSERT_LT(P[0], P[1]);
        if (p > 0) {
            ASSERT_LT(topo.tseps[p - 1], P);
        }
        const auto& e0 = topo.edges[P[0]];
        const auto& e1 = topo.edges[P[1]];
        const int shared = (e0[0] == e1[0]) + (e0[0] == e1[1]) + (e0[1] == e1[0]) + (e0[1] == e1[1]);
        ASSERT_LE(shared, 1);
        ASSERT_EQ(topo.tsep_opposite[p], shared == 0 ? 1 : 0);
        // Targets: diagonal exactly where the ends coincide, else the edge
        // joining them, transposed iff it runs the other way.
        int diagonals = 0;
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) {
                const Target t = topo.tsep_targets[p][2 * i + j];
                const index_t u = e0[i], w = e1[j];
                if (u == w) {
                    ASSERT_EQ(t, kDiagonalTarget);
                    ++diagonals;
                } else {
                    const auto& e2 = topo.edges[target_edge(t)];
                    ASSERT_EQ(e2[0], std::min(u, w));
                    ASSERT_EQ(e2[1], std::max(u, w));
                    ASSERT_EQ(target_transposed(t), u > w);
                }
            }
        ASSERT_EQ(diagonals, shared);
    }
    // CSR adjacencies agree with the lists.
    for (index_t v = 0; v < topo.num_vertices; ++v)
        for (index_t e : topo.vertex_edges.row(v)) ASSERT_TRUE(topo.edges[e][0] == v || topo.edges[e][1] == v);
    long incidences = 0;
    for (index_t e = 0; e < topo.num_edges(); ++e)
        for (index_t p : topo.edge_tseps.row(e)) {
            ASSERT_TRUE(topo.tseps[p][0] == e || topo.tseps[p][1] == e);
            ++incidences;
        }
    EXPECT_EQ(incidences, 2L * topo.num_tseps());
    EXPECT_EQ(topo.vertex_edges.items.size(), 2 * topo.edges.size());
    // Lookups.
    for (index_t e = 0; e < topo.num_edges(); e += 7)
        ASSERT_EQ(topo.find_edge(topo.edges[e][1], topo.edges[e][0]), e);
    for (index_t p = 0; p < topo.num_tseps(); p += 11)
        ASSERT_EQ(topo.find_tsep(topo.tseps[p][1], topo.tseps[p][0]), p);
    EXPECT_EQ(topo.find_edge(0, 0), -1);
}

}  // namespace

TEST(Topology, PaperBoxCounts) {
    const Mesh box = make_box(10, 5, 4);
    const Topology topo = build_topology(box);
    EXPECT_EQ(topo.num_vertices, 330);
    EXPECT_EQ(topo.num_tets, 1200);
    EXPECT_EQ(topo.num_edges(), 1749);
    EXPECT_EQ(topo.num_tseps(), 11460);
    EXPECT_EQ(topo.num_opposite_tseps(), 3 * 1200);
    check_structure(box, topo);
}

TEST(Topology, SingleTet) {
    Mesh m;
    m.X = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    m.tets = {0, 1, 2, 3};
    const Topology topo = build_topology(m);
    EXPECT_EQ(topo.num_edges(), 6);
    EXPECT_EQ(topo.num_tseps(), 15);
    EXPECT_EQ(topo.num_opposite_tseps(), 3);
    check_structure(m, topo);
}

TEST(Topology, IdentityTsepsEqualThreeTrianglesPlusThreeTets) {
    for (const auto& [name, mesh] : test::test_meshes(100000)) {
        SCOPED_TRACE(name);
        const Topology topo = build_topology(mesh);
        EXPECT_EQ(topo.num_tseps(), 3 * count_triangles(mesh) + 3L * mesh.num_tets());
        check_structure(mesh, topo);
    }
}

TEST(Topology, SharedMeshCountsMatchReadme) {
    int found = 0;
    for (const auto& info : test::shared_mesh_table()) {
        const std::string prefix = test::shared_mesh_prefix(info.name);
        if (prefix.empty()) continue;
        ++found;
        SCOPED_TRACE(info.name);
        const Mesh mesh = read_tetgen(prefix);
        const Topology topo = build_topology(mesh);
        EXPECT_EQ(topo.num_vertices, info.vertices);
        EXPECT_EQ(topo.num_tets, info.tets);
        EXPECT_EQ(topo.num_edges(), info.edges);
        EXPECT_EQ(topo.num_tseps(), info.tseps);
        EXPECT_EQ(topo.num_opposite_tseps(), 3L * info.tets);
    }
    if (found == 0) GTEST_SKIP() << "no shared meshes under " << test::shared_mesh_dir();
}
