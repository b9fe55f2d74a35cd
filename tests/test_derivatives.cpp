// Calculus checks that do not trust any other implementation: force is the
// gradient of energy, K x the directional derivative of force (central finite
// differences), and the invariances of an elastic energy.
#include <gtest/gtest.h>

#include "lab/deformations.hpp"
#include "edgefem/core/make_box.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {

struct Eval {
    const test::Models<double>& m;
    ModelKind kind;
    double energy(const std::vector<double>& u) const {
        std::vector<double> f(u.size());
        EdgeState<double> st;
        return kind == ModelKind::FE ? edge_forces<ModelKind::FE, true>(m.edge, u.data(), f.data(), st)
                                     : edge_forces<ModelKind::SN, true>(m.edge, u.data(), f.data(), st);
    }
    std::vector<double> force(const std::vector<double>& u) const {
        std::vector<double> f(u.size());
        EdgeState<double> st;
        if (kind == ModelKind::FE)
            edge_forces<ModelKind::FE, false>(m.edge, u.data(), f.data(), st);
        else
            edge_forces<ModelKind::SN, false>(m.edge, u.data(), f.data(), st);
        return f;
    }
    std::vector<double> kx(const std::vector<double>& u, const std::vector<double>& x) const {
        std::vector<double> f(u.size()), y(u.size());
        EdgeState<double> st;
        EdgeStiffness<double> K;
        if (kind == ModelKind::FE) {
            edge_forces<ModelKind::FE, false>(m.edge, u.data(), f.data(), st);
            edge_stiffness_all<ModelKind::FE>(m.edge, st, K);
        } else {
            edge_forces<ModelKind::SN, false>(m.edge, u.data(), f.data(), st);
            edge_stiffness_all<ModelKind::SN>(m.edge, st, K);
        }
        edge_multiply(m.edge, K, x.data(), y.data());
        return y;
    }
};

std::vector<double> wave(std::size_t n, double a, double b) {
    std::vector<double> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = std::sin(a * i + 0.3) * std::cos(b * i);
    return x;
}

std::vector<double> axpy(const std::vector<double>& u, double h, const std::vector<double>& x) {
    std::vector<double> r(u);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] += h * x[i];
    return r;
}

double extent(const Mesh& mesh) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        for (int r = 0; r < 3; ++r) {
            lo[r] = std::min(lo[r], mesh.X[3 * v + r]);
            hi[r] = std::max(hi[r], mesh.X[3 * v + r]);
        }
    return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

}  // namespace

class Derivatives : public ::testing::TestWithParam<ModelKind> {};

TEST_P(Derivatives, ForceIsEnergyGradientAndKxIsForceDerivative) {
    for (const auto& [name, mesh] : test::test_meshes()) {  // every mesh up to 250k tets
        const auto m = test::make_models<double>(mesh);
        const Eval ev{m, GetParam()};
        const double h = 1e-6 * extent(mesh);  // displacement step
        for (auto kind : {Deformation::Twist, Deformation::Random}) {
            SCOPED_TRACE(name + " deformation " + std::to_string(int(kind)));
            const auto u = deformation_displacement(mesh, kind);
            const auto x = wave(u.size(), 0.37, 0.11);
            const auto f = ev.force(u);
            // Directional derivative of the energy along x.
            const double dW = (ev.energy(axpy(u, h, x)) - ev.energy(axpy(u, -h, x))) / (2 * h);
            const double fx = test::dot(f, x);
            EXPECT_NEAR(dW, fx, 1e-6 * std::abs(fx));
            // Directional derivative of the force along x.
            const auto fp = ev.force(axpy(u, h, x)), fm = ev.force(axpy(u, -h, x));
            std::vector<double> df(u.size());
            for (std::size_t i = 0; i < df.size(); ++i) df[i] = (fp[i] - fm[i]) / (2 * h);
            EXPECT_LE(test::rel_diff(ev.kx(u, x), df), 1e-6);
        }
    }
}

TEST_P(Derivatives, EveryForceComponentOfOneTetBox) {
    const Mesh mesh = make_box(1, 1, 1);
    const auto m = test::make_models<double>(mesh);
    const Eval ev{m, GetParam()};
    const auto u = deformation_displacement(mesh, Deformation::Twist);
    const auto f = ev.force(u);
    const double h = 1e-8;
    for (std::size_t i = 0; i < u.size(); ++i) {
        std::vector<double> e(u.size(), 0.0);
        e[i] = 1;
        const double d = (ev.energy(axpy(u, h, e)) - ev.energy(axpy(u, -h, e))) / (2 * h);
        EXPECT_NEAR(d, f[i], 1e-6 * test::max_abs(f)) << "component " << i;
    }
}

TEST_P(Derivatives, ForcesAndTorquesBalanceAndKIsSymmetric) {
    for (const auto& [name, mesh] : test::test_meshes()) {
        const auto m = test::make_models<double>(mesh);
        const Eval ev{m, GetParam()};
        for (auto kind : {Deformation::Twist, Deformation::Random, Deformation::Affine}) {
            SCOPED_TRACE(name + " deformation " + std::to_string(int(kind)));
            const auto u = deformation_displacement(mesh, kind);
            const auto f = ev.force(u);
            double sum[3] = {0, 0, 0}, torque[3] = {0, 0, 0}, scale = 0, tscale = 0;
            for (index_t v = 0; v < mesh.num_vertices(); ++v) {
                const double* fv = &f[3 * v];
                const double x[3] = {mesh.X[3 * v] + u[3 * v], mesh.X[3 * v + 1] + u[3 * v + 1],
                                     mesh.X[3 * v + 2] + u[3 * v + 2]};
                for (int r = 0; r < 3; ++r) sum[r] += fv[r];
                torque[0] += x[1] * fv[2] - x[2] * fv[1];
                torque[1] += x[2] * fv[0] - x[0] * fv[2];
                torque[2] += x[0] * fv[1] - x[1] * fv[0];
                const double fn = std::sqrt(fv[0] * fv[0] + fv[1] * fv[1] + fv[2] * fv[2]);
                scale += fn;
                tscale += fn * std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            }
            for (int r = 0; r < 3; ++r) {
                EXPECT_LE(std::abs(sum[r]), 1e-13 * scale);
                EXPECT_LE(std::abs(torque[r]), 1e-13 * tscale);
            }
            const auto x = wave(u.size(), 0.37, 0.11), y = wave(u.size(), 0.71, 0.05);
            const double xKy = test::dot(x, ev.kx(u, y)), yKx = test::dot(y, ev.kx(u, x));
            EXPECT_LE(std::abs(xKy - yKx), 1e-12 * (std::abs(xKy) + std::abs(yKx)));
        }
    }
}

TEST_P(Derivatives, StiffnessAnnihilatesRigidTranslation) {
    for (const auto& [name, mesh] : test::test_meshes(10000)) {
        SCOPED_TRACE(name);
        const auto m = test::make_models<double>(mesh);
        const Eval ev{m, GetParam()};
        const auto u = deformation_displacement(mesh, Deformation::Twist);
        std::vector<double> t(u.size());
        for (std::size_t i = 0; i < t.size(); ++i) t[i] = (i % 3 == 1) ? 1.0 : 0.0;
        const auto y = ev.kx(u, t);
        EXPECT_EQ(test::max_abs(y), 0.0);  // d = x(V0) - x(V1) is exactly zero
    }
}

INSTANTIATE_TEST_SUITE_P(Models, Derivatives, ::testing::Values(ModelKind::FE, ModelKind::SN),
                         [](const auto& info) { return info.param == ModelKind::FE ? "FE" : "SN"; });
