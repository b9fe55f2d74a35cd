// The tet-local form against the mesh-wide TSEP list: the same g(E), forces,
// energy and per-edge K(E) blocks to round-off (1e-12 double, 1e-5 float),
// on every test mesh and deformation, plain and definite tangent.
#include <gtest/gtest.h>

#include "edgefem/core/deformations.hpp"
#include "edgefem/core/tet_edge_form.hpp"
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
        for (index_t t = topo.num_tets; t < form.num_batches() * kTetLanes<double>; ++t)
            for (int r = 0; r < kFormRows; ++r)
                ASSERT_EQ(form.A[(t / kTetLanes<double> * kFormRows + r) * kTetLanes<double> + t % kTetLanes<double>], 0.0) << name;
    }
}
