// Every integrator against its own recurrence, mode by mode. A bar released
// from a tiny displacement moves as a linear undamped system: each
// integrator is then a linear recurrence that the bar's vibration modes
// (K at rest, the lumped M: lab/linear_modes.hpp, dense eigenvectors from
// the reference back-end's K) decouple exactly, so the simulator's discrete
// trajectory is predicted from outside it: u_n = sum_i phi_i q_i x_i(n),
// x_i the scalar recurrence of x'' = -omega_i^2 x. This checks each
// integrator's whole discrete dynamics at once (period error and
// numerical damping of every mode, at omega dt from 0.2 to 20; the first
// step's start; the parameters beta, gamma, rho_inf), where the order
// tests (test_integrators.cpp) see only the leading error term.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cantilever.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "lab/linear_modes.hpp"

using namespace edgefem;

namespace {

// A 4 x 1 x 1 bar of 1 cm cubes (Y = 1e5 Pa, clamped at x = min, no
// gravity) released from a bend and twist of 1e-9 m: the nonlinear terms
// are ~1e-7 of the linear ones. The integrators follow their recurrences to
// 1e-8 - 5e-8 of the largest displacement, and to 10x less from 1e-10 m:
// what is left is those terms.
constexpr double kAmplitude = 1e-9;

Scene bar() {
    Scene s = test::clamped_box_scene(4, 1, 1, 1e5);
    s.gravity = {0, 0, 0};
    s.solver.newton_tolerance = 1e-12;
    s.solver.cg_tolerance = 1e-12;
    s.solver.cg_max_iterations = 5000;
    s.count_inverted_tets = false;
    const Mesh& m = s.mesh;
    s.initial_displacement.assign(m.X.size(), 0.0);
    for (index_t v = 0; v < m.num_vertices(); ++v) {
        // make_box centres the box: x in [-0.02, 0.02], y and z in [-0.005, 0.005]
        const double t = (m.X[3 * std::size_t(v)] + 0.02) / 0.04, y = m.X[3 * std::size_t(v) + 1],
                     z = m.X[3 * std::size_t(v) + 2];
        s.initial_displacement[3 * std::size_t(v) + 1] = kAmplitude * (t * t - 30 * t * z);
        s.initial_displacement[3 * std::size_t(v) + 2] = kAmplitude * (0.5 * t + 30 * t * y);
    }
    return s;
}

struct Comparison {
    double worst = 0;  // max over the steps of |u_sim - u_modes| / max |u_modes|
    double scale = 0;  // max |u_modes|
};

Comparison compare(Scene s, long steps) {
    const lab::LinearModes md = lab::linear_modes(s);
    const Eigen::VectorXd q = lab::modal_coordinates(md, s.initial_displacement);
    std::vector<std::vector<double>> x;
    for (Eigen::Index i = 0; i < md.omega.size(); ++i)
        x.push_back(lab::mode_history(s.integrator, s.integrator_parameters, md.omega[i], s.dt, steps,
                                      s.rayleigh_alpha, s.rayleigh_beta));
    const std::size_t size = s.mesh.X.size();
    Simulator<double> sim(std::move(s), nullptr, cpu_operator_factory<double>());
    std::vector<std::vector<double>> predicted, simulated;
    for (long k = 1; k <= steps; ++k) {
        sim.step();
        Eigen::VectorXd c(q.size());
        for (Eigen::Index i = 0; i < q.size(); ++i) c[i] = q[i] * x[std::size_t(i)][std::size_t(k)];
        predicted.push_back(lab::modal_displacement(md, c, size));
        simulated.emplace_back(sim.displacement().begin(), sim.displacement().end());
    }
    Comparison r;
    for (const auto& u : predicted)
        for (double v : u) r.scale = std::max(r.scale, std::abs(v));
    for (std::size_t k = 0; k < predicted.size(); ++k)
        for (std::size_t j = 0; j < size; ++j)
            r.worst = std::max(r.worst, std::abs(simulated[k][j] - predicted[k][j]) / r.scale);
    return r;
}

double highest_omega() { return lab::linear_modes(bar()).omega.maxCoeff(); }

}  // namespace

// The modes themselves: M-orthonormal, K phi = omega^2 M phi (K applied by
// the CPU back-end, not the reference one that made them), the rigid-body
// motions excluded by the clamp (the lowest frequency well above zero).
TEST(ModalDynamics, ModesAreMOrthonormalEigenvectorsOfTheBackendsK) {
    const Scene s = bar();
    const lab::LinearModes md = lab::linear_modes(s);
    const auto n = md.omega.size();
    ASSERT_EQ(n, Eigen::Index(3 * (5 * 2 * 2 - 4)));
    const Eigen::MatrixXd gram = md.phi.transpose() * md.mass.asDiagonal() * md.phi;
    EXPECT_LT((gram - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff(), 1e-10);
    auto op = cpu_operator_factory<double>()(s.mesh, s.materials, ModelKind::FE, Method::Edge);
    std::vector<double> zero(s.mesh.X.size(), 0.0), f(s.mesh.X.size()), y(s.mesh.X.size());
    op->forces(zero.data(), f.data(), false);
    op->build_stiffness(false);
    double worst = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
        Eigen::VectorXd unit = Eigen::VectorXd::Zero(n);
        unit[i] = 1;
        const std::vector<double> phi = lab::modal_displacement(md, unit, s.mesh.X.size());
        op->multiply(phi.data(), y.data());
        double r = 0, scale = 0;
        for (Eigen::Index a = 0; a < n; ++a) {
            const std::size_t d = md.dof[std::size_t(a)];
            r = std::max(r, std::abs(y[d] - md.omega[i] * md.omega[i] * md.mass[a] * phi[d]));
            scale = std::max(scale, std::abs(y[d]));
        }
        worst = std::max(worst, r / scale);
    }
    EXPECT_LT(worst, 1e-9);
    EXPECT_GT(md.omega[0], 2 * M_PI * 5);  // clamped: no rigid-body mode
}

// Each implicit integrator at dt = 2 ms (omega dt from ~0.5 to ~25: the
// stiff modes far past what the step resolves, where the schemes differ
// most) over 100 steps, and the explicit ones at omega_max dt = 1.5.
TEST(ModalDynamics, EveryIntegratorFollowsItsRecurrenceModeByMode) {
    const double explicit_dt = 1.5 / highest_omega();
    struct Case {
        Integrator integrator;
        IntegratorParameters parameters;
        Method method = Method::Edge;
        ModelKind model = ModelKind::FE;
    };
    IntegratorParameters damped_newmark;  // first order, damped: gamma > 1/2
    damped_newmark.newmark_beta = 0.3;
    damped_newmark.newmark_gamma = 0.6;
    IntegratorParameters alpha05;
    alpha05.rho_inf = 0.5;
    const std::vector<Case> cases = {
        {Integrator::Explicit, {}},       {Integrator::Verlet, {}},
        {Integrator::SemiImplicit, {}},   {Integrator::Implicit, {}},
        {Integrator::Newmark, {}},        {Integrator::NewmarkLinear, {}},
        {Integrator::Newmark, damped_newmark},
        {Integrator::GeneralizedAlpha, {}}, {Integrator::GeneralizedAlphaLinear, {}},
        {Integrator::GeneralizedAlpha, alpha05},
        {Integrator::Bdf2, {}},           {Integrator::Bdf2Linear, {}},
        // the per-tet method: the same K, so the same modes
        {Integrator::Newmark, {}, Method::Tet}, {Integrator::SemiImplicit, {}, Method::Tet},
        // the spring network: its own K, its own modes
        {Integrator::Newmark, {}, Method::Edge, ModelKind::SN}, {Integrator::Bdf2Linear, {}, Method::Edge, ModelKind::SN},
    };
    for (const Case& c : cases) {
        Scene s = bar();
        s.integrator = c.integrator;
        s.integrator_parameters = c.parameters;
        s.method = c.method;
        s.model = c.model;
        s.dt = is_explicit(c.integrator) ? explicit_dt : 2e-3;
        const Comparison r = compare(std::move(s), 100);
        SCOPED_TRACE(std::string(to_string(c.integrator)) + (c.method == Method::Tet ? " per-tet" : "") + (c.model == ModelKind::SN ? " SN" : "") + " beta " + std::to_string(c.parameters.newmark_beta) +
                     " gamma " + std::to_string(c.parameters.newmark_gamma) + " rho_inf " +
                     std::to_string(c.parameters.rho_inf));
        EXPECT_GT(r.scale, 0.5 * kAmplitude);
        EXPECT_LT(r.worst, 1e-6);
        std::printf("%-26s %-8s beta %.2f gamma %.2f rho_inf %.2f: %.2e of the largest displacement\n",
                    to_string(c.integrator), c.method == Method::Tet ? "per-tet" : c.model == ModelKind::SN ? "edge SN" : "edge", c.parameters.newmark_beta, c.parameters.newmark_gamma,
                    c.parameters.rho_inf, r.worst);
    }
}

// With Rayleigh damping (alpha = 3 /s, beta = 2e-5 s: the stiffest modes
// over-damped, omega_max beta / 2 ~ 0.1) every integrator but verlet (which
// refuses damping) follows its damped recurrence: the damping's place in
// each scheme (implicit in the Newmark family's balance at alpha_f, in
// backward Euler's and BDF2's new velocity; alpha implicit and beta K v at
// the step's start in the explicit step).
TEST(ModalDynamics, EveryIntegratorFollowsItsDampedRecurrence) {
    const double explicit_dt = 1.5 / highest_omega();
    for (Integrator integ : {Integrator::Explicit, Integrator::SemiImplicit, Integrator::Implicit, Integrator::Newmark,
                             Integrator::NewmarkLinear, Integrator::GeneralizedAlpha,
                             Integrator::GeneralizedAlphaLinear, Integrator::Bdf2, Integrator::Bdf2Linear}) {
        Scene s = bar();
        s.integrator = integ;
        s.rayleigh_alpha = 3;
        s.rayleigh_beta = 2e-5;
        s.dt = is_explicit(integ) ? explicit_dt : 2e-3;
        const Comparison r = compare(std::move(s), 100);
        SCOPED_TRACE(to_string(integ));
        EXPECT_GT(r.scale, 0.5 * kAmplitude);
        EXPECT_LT(r.worst, 1e-6);
        std::printf("%-26s damped: %.2e of the largest displacement\n", to_string(integ), r.worst);
    }
}

// The recurrences are not all alike: the prediction of one integrator is
// far from another's trajectory (so agreement above is not a property of
// any reasonable scheme), and far from the exact motion at 2 ms.
TEST(ModalDynamics, TheRecurrencesTellTheIntegratorsApart) {
    Scene s = bar();
    const lab::LinearModes md = lab::linear_modes(s);
    const Eigen::VectorXd q = lab::modal_coordinates(md, s.initial_displacement);
    auto trajectory_end = [&](Integrator integ, const IntegratorParameters& p, bool exact) {
        Eigen::VectorXd c(q.size());
        for (Eigen::Index i = 0; i < q.size(); ++i)
            c[i] = q[i] * (exact ? lab::exact_mode_history(md.omega[i], 2e-3, 100)
                                 : lab::mode_history(integ, p, md.omega[i], 2e-3, 100))[100];
        return lab::modal_displacement(md, c, s.mesh.X.size());
    };
    auto distance = [](const std::vector<double>& a, const std::vector<double>& b) {
        double d = 0, n = 0;
        for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i])), n = std::max(n, std::abs(b[i]));
        return d / n;
    };
    const IntegratorParameters p;
    const auto exact = trajectory_end(Integrator::Newmark, p, true);
    for (Integrator a : {Integrator::Implicit, Integrator::Newmark, Integrator::GeneralizedAlpha, Integrator::Bdf2}) {
        EXPECT_GT(distance(trajectory_end(a, p, false), exact), 1e-3) << to_string(a);
        for (Integrator b : {Integrator::Implicit, Integrator::Newmark, Integrator::GeneralizedAlpha, Integrator::Bdf2}) {
            if (a != b) {
                EXPECT_GT(distance(trajectory_end(a, p, false), trajectory_end(b, p, false)), 1e-3);
            }
        }
    }
}

// What the recurrences do not model is refused by name, and so are vectors
// of the wrong length.
TEST(ModalDynamics, WhatTheModesDoNotModelIsAnError) {
    auto message = [](const Scene& s) {
        try {
            lab::linear_modes(s);
        } catch (const InvalidArgument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    Scene loaded = bar();
    loaded.gravity = {0, 0, -9.81};
    EXPECT_NE(message(loaded).find("gravity"), std::string::npos) << message(loaded);
    Scene held = bar();
    held.prescribed.push_back({held.mesh.num_vertices() - 1, {0, 0, 0}});
    EXPECT_NE(message(held).find("prescribed"), std::string::npos) << message(held);
    Scene big = test::clamped_box_scene(30, 6, 6, 1e5);
    big.gravity = {0, 0, 0};
    EXPECT_NE(message(big).find("free dofs"), std::string::npos) << message(big);
    Scene bad = bar();
    bad.fixed.push_back(bad.mesh.num_vertices());  // out of range: Scene::validate names it
    EXPECT_NE(message(bad).find("fixed["), std::string::npos) << message(bad);

    const lab::LinearModes md = lab::linear_modes(bar());
    EXPECT_THROW(lab::modal_coordinates(md, std::vector<double>(3)), InvalidArgument);
    EXPECT_THROW(lab::modal_displacement(md, Eigen::VectorXd::Zero(md.omega.size()), 3), InvalidArgument);
    EXPECT_THROW(lab::modal_displacement(md, Eigen::VectorXd::Zero(2), bar().mesh.X.size()), InvalidArgument);
    EXPECT_THROW(lab::mode_history(Integrator::Verlet, {}, 1.0, 1e-3, 10, 1.0, 0.0), InvalidArgument);
}
