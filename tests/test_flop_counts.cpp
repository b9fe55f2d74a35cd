// The hand-derived FLOP formulas of bench/flop_counts.hpp (what bench_paper
// prints as flops_per_tet) against the kernels themselves run on a counting
// scalar: exact equality on generated boxes and on the shared meshes up to
// 10k tets. The double arithmetic on g(E) is outside what the counter sees
// (flop_counts.hpp adds it by hand); this test checks the counted part.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../bench/counting_scalar.hpp"
#include "../bench/flop_counts.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "edgefem/core/make_box.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

TEST(FlopCounts, HandFormulasMatchTheCountingScalarExactly) {
    for (const auto& nm : test::test_meshes(10000)) {
        SCOPED_TRACE(nm.name);
        const Materials mat(Material{1e5, 0.3, 1000});
        const Topology topo = build_topology(nm.mesh);
        const EdgeModel<double> em = make_edge_model<double>(topo, compute_coefficients(nm.mesh, topo, mat));
        const TetModel<double> tm = make_tet_model<double>(nm.mesh, mat);
        const std::vector<double> u = deformation_displacement(nm.mesh, Deformation::Twist);
        const TetEdgeForm<double> form = make_tet_edge_form<double>(nm.mesh, topo, mat);
        const flops::Measured got = flops::count_kernels(em, tm, u, &form);
        const flops::Items n = flops::items_of(em);
        EXPECT_EQ(double(got.edge_force_fe), flops::edge_force(n, ModelKind::FE).counted);
        EXPECT_EQ(double(got.edge_force_sn), flops::edge_force(n, ModelKind::SN).counted);
        EXPECT_EQ(double(got.edge_stiffness_fe), flops::edge_stiffness(n, ModelKind::FE).counted);
        EXPECT_EQ(double(got.edge_stiffness_sn), flops::edge_stiffness(n, ModelKind::SN).counted);
        EXPECT_EQ(double(got.edge_kx), flops::edge_kx(n).counted);
        EXPECT_EQ(double(got.edge_stiffness_fe_tet_local), flops::edge_stiffness_tet_local(n).counted);
        EXPECT_EQ(double(got.edge_force_fe_tet_local), flops::edge_force_tet_local(n).counted);
        // tet_force computes the energy too (the counting scalar sees it).
        EXPECT_EQ(double(got.tet_force), flops::tet_force(n, true).counted);
        EXPECT_EQ(double(got.tet_stiffness), flops::tet_stiffness(n).counted);
        EXPECT_EQ(double(got.tet_kx), flops::tet_kx(n).counted);
        // The double part on g: SN has none, FE 4 per TSEP + 1 per edge.
        EXPECT_EQ(flops::edge_force(n, ModelKind::SN).total, flops::edge_force(n, ModelKind::SN).counted);
        EXPECT_EQ(flops::edge_force(n, ModelKind::FE).total - flops::edge_force(n, ModelKind::FE).counted,
                  4 * n.P + n.E);
    }
}

TEST(FlopCounts, CountingScalarComputesTheSameForcesAsDouble) {
    const Mesh mesh = make_box(3, 2, 2);
    const Materials mat(Material{1e5, 0.3, 1000});
    const Topology topo = build_topology(mesh);
    const EdgeModel<double> em = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
    const auto u = deformation_displacement(mesh, Deformation::Twist);
    std::vector<double> f(u.size());
    EdgeState<double> st;
    edge_forces<ModelKind::FE, false>(em, u.data(), f.data(), st);
    const auto ec = flops::counted_model(em);
    std::vector<flops::Counted> uc(u.begin(), u.end()), fc(u.size());
    EdgeState<flops::Counted> sc;
    edge_forces<ModelKind::FE, false>(ec, uc.data(), fc.data(), sc);
    double scale = 0;
    for (double x : f) scale = std::max(scale, std::abs(x));
    for (std::size_t i = 0; i < f.size(); ++i) EXPECT_NEAR(f[i], fc[i].v, 1e-13 * scale) << i;
}
