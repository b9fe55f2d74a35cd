// The tet-local form against the mesh-wide TSEP list: the same g(E), forces,
// energy and per-edge K(E) blocks to round-off (1e-12 double, 1e-5 float),
// on every test mesh and deformation, plain and definite tangent. And the
// serial sweeps' tiles: any tile size gives bitwise the results of one
// whole-mesh tile (three plain passes), in any vertex numbering.
#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "lab/deformations.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "cpu/tet_edge_form.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;
using test::rel_diff;

namespace {

template <class S, bool Definite>
void compare(const Mesh& mesh, const std::string& name, double tol) {
    const Materials mat(Material{1e5, 0.3, 1000});
    const auto m = test::make_models<S>(mesh, mat);
    const TetEdgeForm<S> form = make_tet_edge_form<S>(mesh, m.topo, mat);
    for (Deformation d : {Deformation::Twist, Deformation::Random, Deformation::Rotate}) {
        const auto u = test::cast<S>(deformation_displacement(mesh, d));
        std::vector<S> f0(u.size()), f1(u.size());
        EdgeState<S> s0, s1;
        EdgeStiffness<S> K0, K1;
        const double W0 = edge_forces<ModelKind::FE, true>(m.edge, u.data(), f0.data(), s0);
        const double W1 = tet_form_forces<ModelKind::FE, true>(m.edge, form, u.data(), f1.data(), s1);
        edge_stiffness_all<ModelKind::FE, Definite>(m.edge, s0, K0);
        tet_form_stiffness_all<ModelKind::FE, Definite>(m.edge, form, s1, K1);
        // Drop the sink block: only the TSEP path writes it.
        K0.K.resize(9 * std::size_t(m.edge.num_edges()));
        K1.K.resize(9 * std::size_t(m.edge.num_edges()));
        SCOPED_TRACE(name + " deformation " + std::to_string(int(d)));
        EXPECT_LE(rel_diff(f1, f0), tol);
        EXPECT_LE(rel_diff(s1.g, s0.g), tol);
        EXPECT_LE(rel_diff(K1.K, K0.K), tol);
        EXPECT_NEAR(W1, W0, tol * std::abs(W0) + 1e-300);
    }
}

}  // namespace

TEST(TetEdgeForm, MatchesTsepListDouble) {
    for (const auto& [name, mesh] : test::test_meshes(100000)) {
        compare<double, false>(mesh, name, 1e-12);
        compare<double, true>(mesh, name, 1e-12);
    }
}

TEST(TetEdgeForm, MatchesTsepListFloat) {
    for (const auto& [name, mesh] : test::test_meshes(10000)) compare<float, false>(mesh, name, 1e-5);
}

// Every tet sits in one slot with its 6 edges, and padding lanes are inert.
TEST(TetEdgeForm, EdgesAreTheTetsEdges) {
    for (const auto& [name, mesh] : test::test_meshes(10000)) {
        const Topology topo = build_topology(mesh);
        const auto form = make_tet_edge_form<double>(mesh, topo, Materials(Material{}));
        std::vector<int> seen(topo.num_tets, 0);
        for (index_t t = 0; t < topo.num_tets; ++t) {
            const index_t tet = form.slot_tet[t];
            ASSERT_TRUE(tet >= 0 && tet < topo.num_tets && seen[tet]++ == 0) << name << " slot " << t;
            std::array<index_t, 6> a{}, b = topo.tet_edges[tet];
            for (int k = 0; k < 6; ++k) a[k] = form.edge[(t / kTetLanes<double> * 6 + k) * kTetLanes<double> + t % kTetLanes<double>];
            std::sort(a.begin(), a.end());
            std::sort(b.begin(), b.end());
            ASSERT_EQ(a, b) << name << " tet " << t;
        }
        // Padding lanes: A = 0, and only edges that lane 0 of their batch
        // reads (the kernels load every lane; another edge may be another
        // thread's, written while it is read).
        constexpr int L = kTetLanes<double>;
        for (index_t t = topo.num_tets; t < form.num_batches() * L; ++t) {
            const index_t b = t / L;
            for (int r = 0; r < kFormRows; ++r)
                ASSERT_EQ(form.A[(b * kFormRows + r) * L + t % L], 0.0) << name;
            for (int k = 0; k < 6; ++k)
                ASSERT_EQ(form.edge[(b * 6 + k) * L + t % L], form.edge[(b * 6 + k) * L]) << name << " lane " << t % L;
        }
    }
}


namespace {

// The mesh with its vertices renumbered at random: edges then reach far
// across the numbering, the hardest case for the tiles' bounds.
Mesh shuffled(const Mesh& mesh, unsigned seed) {
    std::vector<index_t> to(mesh.num_vertices());
    std::iota(to.begin(), to.end(), index_t(0));
    std::mt19937 rng(seed);
    std::shuffle(to.begin(), to.end(), rng);
    Mesh s;
    s.X.resize(mesh.X.size());
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        for (int c = 0; c < 3; ++c) s.X[3 * std::size_t(to[v]) + c] = mesh.X[3 * std::size_t(v) + c];
    s.tets = mesh.tets;
    for (auto& v : s.tets) v = to[v];
    s.region = mesh.region;
    return s;
}

template <class S>
void tiles_bitwise(const Mesh& mesh, const std::string& name, int& rings) {
    const Materials mat(Material{1e5, 0.3, 1000});
    const auto m = test::make_models<S>(mesh, mat);
    TetEdgeForm<S> form = make_tet_edge_form<S>(mesh, m.topo, mat);
    const auto u = test::cast<S>(deformation_displacement(mesh, Deformation::Random));
    // Reference: one tile, the whole mesh.
    form.tiles.clear();
    std::vector<S> f0(u.size());
    EdgeState<S> s0;
    EdgeStiffness<S> K0;
    const double W0 = tet_form_forces<ModelKind::FE, true>(m.edge, form, u.data(), f0.data(), s0);
    tet_form_stiffness_all<ModelKind::FE, false>(m.edge, form, s0, K0);
    for (index_t per_tile : {1, 3, 64, kFormTileBatches, form.num_batches() + 1}) {
        SCOPED_TRACE(name + ", " + std::to_string(per_tile) + " batches per tile");
        form.tiles = plan_form_tiles(form, m.topo.edges, m.topo.first_edge, per_tile);
        ASSERT_FALSE(form.tiles.empty());
        const FormTile& last = form.tiles.back();
        EXPECT_EQ(last.batch_end, form.num_batches());
        EXPECT_EQ(last.edge_end, m.edge.num_edges());
        EXPECT_EQ(last.vertex_end, m.edge.num_vertices);
        EXPECT_EQ(last.zero_end, m.edge.num_vertices);
        // Garbage in f first: the tiles must zero every entry they scatter to.
        std::vector<S> f1(u.size(), S(7));
        EdgeState<S> s1;
        EdgeStiffness<S> K1;
        const double W1 = tet_form_forces<ModelKind::FE, true>(m.edge, form, u.data(), f1.data(), s1);
        tet_form_stiffness_all<ModelKind::FE, false>(m.edge, form, s1, K1);
        EXPECT_TRUE(f1 == f0);
        EXPECT_TRUE(s1.g == s0.g);
        EXPECT_TRUE(K1.K == K0.K);
        EXPECT_EQ(W1, W0);
        // Without the state: the same sweep on a ring (small tiles wrap it
        // many times), bitwise.
        FormRing<S> ring = make_form_ring(form, m.edge.edge_first);
        if (form.tiles.size() < 2) {
            EXPECT_TRUE(ring.empty());
            continue;
        }
        if (ring.empty()) continue;  // the ring would not be shorter than the edge list
        EXPECT_GE(index_t(ring.g.size()), form_live_edges(form, m.edge.edge_first));
        EXPECT_LT(index_t(ring.g.size()), m.edge.num_edges());
        std::vector<S> f2(u.size(), S(7));
        const double W2 = tet_form_forces_ring<ModelKind::FE, true>(m.edge, form, u.data(), f2.data(), ring);
        EXPECT_TRUE(f2 == f0);
        EXPECT_EQ(W2, W0);
        ++rings;
    }
}

}  // namespace

TEST(TetEdgeForm, TilesAreBitwiseTheWholeMeshPasses) {
    int rings = 0;
    for (const auto& [name, mesh] : test::test_meshes(10000)) {
        tiles_bitwise<double>(mesh, name, rings);
        tiles_bitwise<double>(shuffled(mesh, 7), name + " shuffled", rings);
        tiles_bitwise<float>(mesh, name, rings);
    }
    EXPECT_GT(rings, 0);  // the ring path ran
}

TEST(TetEdgeForm, RingMustFitTheTiles) {
    const Mesh mesh = make_box(24, 8, 8, 0.01);  // a ring is shorter than its edge list
    const Materials mat(Material{1e5, 0.3, 1000});
    const auto m = test::make_models<double>(mesh, mat);
    auto form = make_tet_edge_form<double>(mesh, m.topo, mat);
    const auto u = deformation_displacement(mesh, Deformation::Random);
    std::vector<double> f(u.size());
    form.tiles = plan_form_tiles(form, m.topo.edges, m.topo.first_edge, 1);
    FormRing<double> ring = make_form_ring(form, m.edge.edge_first);
    ASSERT_FALSE(ring.empty());
    EXPECT_NO_THROW((tet_form_forces_ring<ModelKind::FE, false>(m.edge, form, u.data(), f.data(), ring)));
    // Larger tiles keep more edges alive than the ring holds.
    for (index_t per_tile = 2; per_tile < form.num_batches(); per_tile *= 2) {
        form.tiles = plan_form_tiles(form, m.topo.edges, m.topo.first_edge, per_tile);
        if (form_live_edges(form, m.edge.edge_first) > index_t(ring.g.size())) break;
    }
    ASSERT_GT(form.tiles.size(), 1u);
    ASSERT_GT(form_live_edges(form, m.edge.edge_first), index_t(ring.g.size()));
    EXPECT_THROW((tet_form_forces_ring<ModelKind::FE, false>(m.edge, form, u.data(), f.data(), ring)), InvalidArgument);
    form.tiles.clear();  // one tile: no ring at all
    EXPECT_TRUE(make_form_ring(form, m.edge.edge_first).empty());
    EXPECT_THROW((tet_form_forces_ring<ModelKind::FE, false>(m.edge, form, u.data(), f.data(), ring)), InvalidArgument);
}

TEST(TetEdgeForm, TilePlanRejectsNonsense) {
    const auto meshes = test::test_meshes(10000);
    const Mesh& mesh = meshes.front().mesh;
    const auto m = test::make_models<double>(mesh, Materials(Material{}));
    const auto form = make_tet_edge_form<double>(mesh, m.topo, Materials(Material{}));
    EXPECT_THROW(plan_form_tiles(form, m.topo.edges, m.topo.first_edge, 0), InvalidArgument);
    std::vector<index_t> short_first(m.topo.first_edge.begin(), m.topo.first_edge.end() - 1);
    EXPECT_THROW(plan_form_tiles(form, m.topo.edges, short_first, 16), InvalidArgument);
    const index_t nb = form.num_batches(), ne = m.topo.num_edges(), nv = mesh.num_vertices();
    for (const FormTileRange& bad : {FormTileRange{0, nb + 1, 0, ne, 0, nv}, FormTileRange{2, 1, 0, ne, 0, nv},
                                     FormTileRange{0, nb, 0, ne + 1, 0, nv}, FormTileRange{0, nb, 0, ne, 0, nv + 1},
                                     FormTileRange{0, nb, 0, ne, -1, nv}})
        EXPECT_THROW(plan_form_tiles(form, m.topo.edges, m.topo.first_edge, 16, bad), InvalidArgument);
}
