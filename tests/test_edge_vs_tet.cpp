// The edge-based kernels against the conventional per-tet method: the same
// energy, forces and K x to round-off (1e-12 double, 1e-5 float), on every
// test mesh, at rest, twisted+stretched, rigidly rotated and perturbed.
#include <gtest/gtest.h>

#include "lab/deformations.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;
using test::rel_diff;

namespace {

struct Result {
    double energy;
    std::vector<double> f, kx;
};

template <class S>
Result edge_eval(const test::Models<S>& m, const std::vector<double>& u, const std::vector<double>& x) {
    const auto us = test::cast<S>(u), xs = test::cast<S>(x);
    std::vector<S> f(us.size()), y(us.size());
    EdgeState<S> st;
    EdgeStiffness<S> K;
    const double W = edge_forces<ModelKind::FE, true>(m.edge, us.data(), f.data(), st);
    edge_stiffness_all<ModelKind::FE>(m.edge, st, K);
    edge_multiply(m.edge, K, xs.data(), y.data());
    return {W, test::cast<double>(f), test::cast<double>(y)};
}

template <class S>
Result tet_eval(const test::Models<S>& m, const std::vector<double>& u, const std::vector<double>& x) {
    const auto us = test::cast<S>(u), xs = test::cast<S>(x);
    std::vector<S> f(us.size()), y(us.size());
    TetStiffness<S> K;
    const double W = tet_forces_stiffness<true>(m.tet, us.data(), f.data(), K);
    tet_multiply(m.tet, K, xs.data(), y.data());
    return {W, test::cast<double>(f), test::cast<double>(y)};
}

std::vector<double> direction(std::size_t n) {
    std::vector<double> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = std::sin(1.3 * i + 0.2) + 0.5 * std::cos(0.7 * i);
    return x;
}

// Force scale for "zero" checks: Y * (mean edge length)^2 * strain 1.
double force_scale(const Mesh& mesh, const Coefficients& coef) {
    double h = 0;
    for (double H : coef.H) h += std::sqrt(H);
    h /= coef.H.size();
    (void)mesh;
    return 1e5 * h * h;
}

}  // namespace

TEST(EdgeVsTet, DoubleAgreesTo1e12) {
    for (const auto& [name, mesh] : test::test_meshes()) {
        const auto m = test::make_models<double>(mesh);
        const auto x = direction(mesh.X.size());
        for (auto kind : {Deformation::Twist, Deformation::Affine, Deformation::Random}) {
            SCOPED_TRACE(name + " deformation " + std::to_string(int(kind)));
            const auto u = deformation_displacement(mesh, kind);
            const Result e = edge_eval(m, u, x), t = tet_eval(m, u, x);
            EXPECT_LE(std::abs(e.energy - t.energy), 1e-12 * std::abs(t.energy));
            EXPECT_LE(rel_diff(e.f, t.f), 1e-12);
            EXPECT_LE(rel_diff(e.kx, t.kx), 1e-12);
            // Third route: per-tet K x without stored blocks.
            std::vector<double> y(u.size());
            tet_multiply_matrix_free(m.tet, u.data(), x.data(), y.data());
            EXPECT_LE(rel_diff(e.kx, y), 1e-12);
        }
    }
}

TEST(EdgeVsTet, FloatAgreesTo1e5) {
    for (const auto& [name, mesh] : test::test_meshes()) {
        const auto md = test::make_models<double>(mesh);
        const auto mf = test::make_models<float>(mesh);
        const auto x = direction(mesh.X.size());
        for (auto kind : {Deformation::Twist, Deformation::Random}) {
            SCOPED_TRACE(name + " deformation " + std::to_string(int(kind)));
            const auto u = deformation_displacement(mesh, kind);
            const Result ed = edge_eval(md, u, x), ef = edge_eval(mf, u, x), tf = tet_eval(mf, u, x);
            EXPECT_LE(rel_diff(ef.f, ed.f), 1e-5);
            EXPECT_LE(rel_diff(tf.f, ed.f), 1e-5);
            EXPECT_LE(rel_diff(ef.f, tf.f), 1e-5);
            EXPECT_LE(rel_diff(ef.kx, ed.kx), 1e-5);
            EXPECT_LE(rel_diff(tf.kx, ed.kx), 1e-5);
            EXPECT_LE(std::abs(ef.energy - ed.energy), 1e-5 * ed.energy);
        }
    }
}

TEST(EdgeVsTet, ZeroAtRestAndUnderRigidRotation) {
    for (const auto& [name, mesh] : test::test_meshes()) {
        SCOPED_TRACE(name);
        const auto m = test::make_models<double>(mesh);
        const double fs = force_scale(mesh, m.coef);
        const auto x = direction(mesh.X.size());
        const auto twist = edge_eval(m, deformation_displacement(mesh, Deformation::Twist), x);
        const std::vector<double> rest(mesh.X.size(), 0.0);
        const auto r0 = edge_eval(m, rest, x);
        EXPECT_EQ(r0.energy, 0.0);
        EXPECT_EQ(test::max_abs(r0.f), 0.0);
        for (const Result& r : {edge_eval(m, deformation_displacement(mesh, Deformation::Rotate), x),
                                tet_eval(m, deformation_displacement(mesh, Deformation::Rotate), x)}) {
            EXPECT_LE(test::max_abs(r.f), 1e-12 * fs);
            EXPECT_LE(std::abs(r.energy), 1e-12 * twist.energy);
        }
    }
}
