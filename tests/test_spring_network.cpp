// The spring-network (SN) model: the FE kernels with every TSEP term dropped,
// and a different material from FE.
#include <gtest/gtest.h>

#include "lab/deformations.hpp"
#include "edgefem/core/make_box.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

TEST(SpringNetwork, EqualsFeWithoutTsepTerms) {
    for (const auto& [name, mesh] : test::test_meshes(10000)) {
        SCOPED_TRACE(name);
        auto m = test::make_models<double>(mesh);
        const auto u = deformation_displacement(mesh, Deformation::Twist);
        std::vector<double> f_sn(u.size()), f_fe0(u.size()), y_sn(u.size()), y_fe0(u.size()), x(u.size());
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::cos(0.3 * i);
        EdgeState<double> st;
        EdgeStiffness<double> K;
        const double W_sn = edge_forces<ModelKind::SN, true>(m.edge, u.data(), f_sn.data(), st);
        edge_stiffness_all<ModelKind::SN>(m.edge, st, K);
        edge_multiply(m.edge, K, x.data(), y_sn.data());
        // Independent energy: sum_E L(E) zeta(E)^2 / 4 from the double coefficients.
        double W_ref = 0;
        for (index_t e = 0; e < m.topo.num_edges(); ++e) {
            double p2 = 0;
            for (int r = 0; r < 3; ++r) {
                const double p = m.coef.rest_edge[3 * e + r] + u[3 * m.topo.edges[e][0] + r] - u[3 * m.topo.edges[e][1] + r];
                p2 += p * p;
            }
            W_ref += m.coef.LE[e] * (p2 - m.coef.H[e]) * (p2 - m.coef.H[e]) / 4;
        }
        EXPECT_NEAR(W_sn, W_ref, 1e-10 * W_ref);
        // FE with L(P) = 0 runs the TSEP loops and adds exact zeros: bitwise equal.
        std::fill(m.edge.LP.begin(), m.edge.LP.end(), 0.0);
        edge_forces<ModelKind::FE, false>(m.edge, u.data(), f_fe0.data(), st);
        edge_stiffness_all<ModelKind::FE>(m.edge, st, K);
        edge_multiply(m.edge, K, x.data(), y_fe0.data());
        EXPECT_EQ(f_sn, f_fe0);
        EXPECT_EQ(y_sn, y_fe0);
    }
}

namespace {
// Lateral strain at which a box stretched 5% along x is in equilibrium
// laterally: the minimiser over s of W(x -> 1.05 x, (y, z) -> s (y, z)) - 1.
double lateral_strain(ModelKind kind, double poisson) {
    const Mesh mesh = make_box(5, 5, 5);
    const auto m = test::make_models<double>(mesh, Material{1e5, poisson, 1000});
    auto energy = [&](double s) {
        std::vector<double> u(mesh.X.size()), f(mesh.X.size());
        for (index_t v = 0; v < mesh.num_vertices(); ++v) {
            u[3 * v] = 0.05 * mesh.X[3 * v];
            u[3 * v + 1] = (s - 1) * mesh.X[3 * v + 1];
            u[3 * v + 2] = (s - 1) * mesh.X[3 * v + 2];
        }
        EdgeState<double> st;
        return kind == ModelKind::FE ? edge_forces<ModelKind::FE, true>(m.edge, u.data(), f.data(), st)
                                     : edge_forces<ModelKind::SN, true>(m.edge, u.data(), f.data(), st);
    };
    double a = 0.8, b = 1.2;  // golden-section search; W is convex in s here
    for (int i = 0; i < 100; ++i) {
        const double m1 = a + 0.381966 * (b - a), m2 = a + 0.618034 * (b - a);
        (energy(m1) < energy(m2) ? b : a) = (energy(m1) < energy(m2) ? m2 : m1);
    }
    return 0.5 * (a + b) - 1;
}
}  // namespace

// FE follows its Poisson ratio (lateral strain ~ -nu * 5%: expansion for
// nu < 0, none for nu = 0); SN always contracts, whatever nu: it cannot
// represent the FE material's Poisson effect.
TEST(SpringNetwork, LateralResponseDiffersFromFe) {
    for (double nu : {-0.3, 0.0, 0.3}) {
        SCOPED_TRACE(nu);
        const double fe = lateral_strain(ModelKind::FE, nu), sn = lateral_strain(ModelKind::SN, nu);
        EXPECT_LT(sn, -0.005);
        if (nu == 0.0)
            EXPECT_NEAR(fe, 0.0, 1e-6);
        else
            EXPECT_NEAR(fe, -nu * 0.05, 0.1 * nu * 0.05 * (nu > 0 ? 1 : -1));
    }
    EXPECT_GT(lateral_strain(ModelKind::FE, -0.3), 0.01);  // FE expands where SN contracts
}
