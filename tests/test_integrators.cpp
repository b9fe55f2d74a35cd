// The time integrators (docs/dynamics.md, "Integrators"): convergence
// orders measured by halving dt against a much finer run, energy
// conservation of the trapezoidal rule and velocity Verlet over many
// periods, generalized-alpha at rho_inf = 1 against Newmark, the reference
// back-end against the CPU back-end, step halving with history, and the
// energy guard catching a trapezoidal blow-up.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "edgefem/core/backend.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "cantilever.hpp"
#include "forwarding_operator.hpp"
#include "models.hpp"

using namespace edgefem;

namespace {

// A small soft cantilever (3 x 1 x 1 cubes, Y = 2e3 Pa) released under
// gravity: it swings through large (nonlinear) deflections, and every one
// of its frequencies is resolved at the steps below (smooth solution).
Scene swing(Integrator integ, double dt) {
    Scene s = test::clamped_box_scene(3, 1, 1, 2e3);
    s.integrator = integ;
    s.dt = dt;
    s.solver.cg_tolerance = 1e-12;
    s.solver.cg_max_iterations = 2000;
    s.solver.newton_tolerance = 1e-12;
    return s;
}

std::vector<double> run_to(Scene s, double t_end) {
    const int n = int(std::lround(t_end / s.dt));
    Simulator<double> sim(std::move(s));
    for (int k = 0; k < n; ++k) sim.step();
    const auto u = sim.displacement();
    return {u.begin(), u.end()};
}

double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0;
    for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
    return d;
}

double max_abs(const std::vector<double>& a) {
    double d = 0;
    for (double x : a) d = std::max(d, std::abs(x));
    return d;
}

// The second-order integrators.
const Integrator kSecondOrder[] = {Integrator::Newmark,          Integrator::NewmarkLinear,
                                   Integrator::GeneralizedAlpha, Integrator::GeneralizedAlphaLinear,
                                   Integrator::Bdf2,             Integrator::Bdf2Linear,
                                   Integrator::Verlet};

struct Order {
    Integrator integ;
    double expected;
};

}  // namespace

// Errors at t = 0.1 s for dt, dt / 2, dt / 4 (dt = 1 ms) against the same
// integrator at dt / 32; the order is log2 of successive error ratios.
TEST(Integrators, MeasuredConvergenceOrders) {
    const double t_end = 0.1, dt = 1e-3;
    for (const Order& o : {Order{Integrator::Explicit, 1}, Order{Integrator::SemiImplicit, 1},
                           Order{Integrator::Implicit, 1}, Order{Integrator::Newmark, 2},
                           Order{Integrator::NewmarkLinear, 2}, Order{Integrator::GeneralizedAlpha, 2},
                           Order{Integrator::GeneralizedAlphaLinear, 2}, Order{Integrator::Bdf2, 2},
                           Order{Integrator::Bdf2Linear, 2}, Order{Integrator::Verlet, 2}}) {
        SCOPED_TRACE(to_string(o.integ));
        const std::vector<double> ref = run_to(swing(o.integ, dt / 32), t_end);
        std::vector<double> err;
        for (double h : {dt, dt / 2, dt / 4}) err.push_back(max_diff(run_to(swing(o.integ, h), t_end), ref));
        const double p1 = std::log2(err[0] / err[1]), p2 = std::log2(err[1] / err[2]);
        std::printf("%-26s errors %.3e %.3e %.3e (of %.3e) orders %.2f %.2f\n", to_string(o.integ), err[0], err[1],
                    err[2], max_abs(ref), p1, p2);
        EXPECT_GE(std::min(p1, p2), o.expected == 2 ? 1.8 : 0.9);
        EXPECT_LE(std::max(p1, p2), o.expected + 1.0);  // not an order it cannot have
    }
}

// Stiffness damping in the explicit step (beta K(u) v, K built at each
// step's u): against an independent reference, the trapezoidal rule by
// Newton with the same beta at dt / 32, symplectic Euler's errors at dt,
// dt / 2 and dt / 4 fall at first order, and the same steps without beta
// stay at least 10x further from that reference (beta acts on the
// explicit step as it does on the implicit ones).
TEST(Integrators, ExplicitStiffnessDampingConvergesAtFirstOrder) {
    const double t_end = 0.1, dt = 5e-4, beta = 2e-3;
    Scene ref_scene = swing(Integrator::Newmark, dt / 32);
    ref_scene.rayleigh_beta = beta;
    const std::vector<double> ref = run_to(ref_scene, t_end);
    std::vector<double> err, undamped;
    for (double h : {dt, dt / 2, dt / 4}) {
        Scene s = swing(Integrator::Explicit, h);
        s.rayleigh_beta = beta;
        err.push_back(max_diff(run_to(s, t_end), ref));
        undamped.push_back(max_diff(run_to(swing(Integrator::Explicit, h), t_end), ref));
    }
    const double p1 = std::log2(err[0] / err[1]), p2 = std::log2(err[1] / err[2]);
    std::printf("explicit, beta %.0e: errors %.3e %.3e %.3e (of %.3e), orders %.2f %.2f; without beta %.3e %.3e %.3e\n",
                beta, err[0], err[1], err[2], max_abs(ref), p1, p2, undamped[0], undamped[1], undamped[2]);
    EXPECT_GE(std::min(p1, p2), 0.9);
    EXPECT_LE(std::max(p1, p2), 2.0);
    for (int k = 0; k < 3; ++k) EXPECT_GE(undamped[std::size_t(k)], 10 * err[std::size_t(k)]);
}

namespace {

// An undamped swing in the linear regime: a 4 x 1 x 1 cantilever (Y = 2e4
// Pa, first period ~0.2 s) under a weak gravity (0.2 m/s^2: the tip moves
// ~0.5 mm, 1 % of the length).
Scene linear_swing(Integrator integ, double dt) {
    Scene s = test::clamped_box_scene(4, 1, 1, 2e4);
    s.gravity = {0, 0, -0.2};
    s.integrator = integ;
    s.dt = dt;
    s.solver.newton_tolerance = 1e-12;
    s.solver.cg_tolerance = 1e-12;
    s.solver.cg_max_iterations = 2000;
    return s;
}

// The largest |E(t) - E(0)| over the run, relative to the largest kinetic
// + elastic energy seen.
double energy_error(Scene s, double t_end) {
    const int n = int(std::lround(t_end / s.dt));
    Simulator<double> sim(std::move(s));
    const double E0 = sim.energies().total();
    double worst = 0, scale = 0;
    for (int k = 0; k < n; ++k) {
        sim.step();
        const Energies e = sim.energies();
        worst = std::max(worst, std::abs(e.total() - E0));
        scale = std::max(scale, e.kinetic + e.elastic);
    }
    return worst / scale;
}

}  // namespace

// Over 2 s (about ten periods): the trapezoidal rule conserves the energy
// of a linear system exactly, so what is left is the small nonlinearity and
// the Newton tolerance: within 1e-5 of the motion's energy (1.5e-6 seen;
// linearised: 1e-4, 7e-6 seen); velocity Verlet's energy oscillates by
// O(dt^2) without drift: within 1e-5 (2.2e-6 seen). Backward Euler, for
// contrast, loses 30 % of it.
TEST(Integrators, TrapezoidalAndVerletConserveEnergyOverManyPeriods) {
    const double newmark = energy_error(linear_swing(Integrator::Newmark, 2e-3), 2.0);
    const double newmark_linear = energy_error(linear_swing(Integrator::NewmarkLinear, 2e-3), 2.0);
    const double verlet = energy_error(linear_swing(Integrator::Verlet, 1e-4), 2.0);
    const double euler = energy_error(linear_swing(Integrator::Implicit, 2e-3), 2.0);
    std::printf("energy error: newmark %.3e, newmark-linear %.3e, verlet %.3e, backward Euler %.3e\n", newmark,
                newmark_linear, verlet, euler);
    EXPECT_LT(newmark, 1e-5);
    EXPECT_LT(newmark_linear, 1e-4);
    EXPECT_LT(verlet, 1e-5);
    EXPECT_GT(euler, 0.1);
}

// Generalized-alpha at rho_inf = 1 (alpha_m = alpha_f = 1/2, beta = 1/4,
// gamma = 1/2) balances the average of the equations at the step's two
// ends, which equals Newmark's balance at the end when the start's holds:
// the same trajectory to the Newton tolerance. At rho_inf = 0.5 it is a
// different (damping) scheme.
TEST(Integrators, GeneralizedAlphaAtRhoOneIsTrapezoidalNewmark) {
    Scene ga = swing(Integrator::GeneralizedAlpha, 2e-3);
    ga.rayleigh_alpha = 0.3;
    ga.integrator_parameters.rho_inf = 1;
    Scene nm = ga;
    nm.integrator = Integrator::Newmark;
    const std::vector<double> a = run_to(ga, 0.2), b = run_to(nm, 0.2);
    EXPECT_LE(max_diff(a, b), 1e-8 * max_abs(b));
    ga.integrator_parameters.rho_inf = 0.5;
    EXPECT_GT(max_diff(run_to(ga, 0.2), b), 1e-5 * max_abs(b));
}

// An operator whose forces are NaN at `count` calls in a row: the step that makes them
// fails and is retried as two halves.
class FaultOperator final : public test::ForwardingOperator {
public:
    FaultOperator(std::unique_ptr<ElasticOperator<double>> op, int fail_at, int count)
        : ForwardingOperator(std::move(op)), fail_at_(fail_at), count_(count) {}
    double forces(const double* u, double* f, bool energy) override {
        const double W = op_->forces(u, f, energy);
        if (++calls_ >= fail_at_ && calls_ < fail_at_ + count_) f[3 * std::size_t(num_vertices()) - 1] = NAN;  // a free dof
        return W;
    }

private:
    int fail_at_, count_, calls_ = 0;
};

// A step that fails is retried as two halves with the integrator's history
// (Newmark's acceleration, BDF2's previous step) restored, and the next
// steps run as halves too (the halving is remembered): the trajectory stays
// within 0.3 % of the plain run's plus twice the plain run's own
// difference from a run at dt / 2 (mixing the two steps may move it more
// than the uniform dt / 2 does: 1.6x that, BDF2's variable-step formula at
// the changes; 0.1-1.0x in the others). The failures: NaN forces for three
// force passes (the linearised and explicit steps), for 45 (the Newton
// forms: its line search takes 40 tries).
TEST(Integrators, StepHalvingRestoresTheHistory) {
    for (Integrator integ : kSecondOrder) {
        SCOPED_TRACE(to_string(integ));
        Scene s = swing(integ, integ == Integrator::Verlet ? 1e-4 : 4e-3);
        const std::vector<double> plain = run_to(s, 0.2);
        Scene half = s;
        half.dt /= 2;
        const double step_error = max_diff(run_to(half, 0.2), plain);
        s.solver.max_step_halvings = 4;
        const bool newton = integ == Integrator::Newmark || integ == Integrator::GeneralizedAlpha || integ == Integrator::Bdf2;
        const OperatorFactory<double> faulty = [newton](const Mesh& m, const Materials& mat, ModelKind k, Method me)
            -> std::unique_ptr<ElasticOperator<double>> {
            return std::make_unique<FaultOperator>(make_cpu_operator<double>(m, mat, k, me), 40, newton ? 45 : 3);
        };
        Simulator<double> sim(s, nullptr, faulty);
        long halvings = 0, remembered = 0;  // steps run halved without a failure of their own
        const int n = int(std::lround(0.2 / s.dt));
        int last_depth = 0;
        for (int k = 0; k < n; ++k) {
            const StepStats& st = sim.step();
            halvings += st.halvings;
            if (st.halvings == 0 && st.substep_depth > 0) ++remembered;
            last_depth = st.substep_depth;
        }
        const std::vector<double> u(sim.displacement().begin(), sim.displacement().end());
        std::printf("%s: %ld halvings, %ld steps halved after them, difference %.3e of %.3e (dt / 2: %.3e)\n",
                    to_string(integ), halvings, remembered, max_diff(u, plain), max_abs(plain), step_error);
        EXPECT_GE(halvings, 1);
        EXPECT_GE(remembered, 1);  // the halving is remembered
        // ... and forgotten once the fault has passed (Verlet's 2000 steps):
        // a hold of 64 steps per level (step_control.hpp).
        if (n > 1000) {
            EXPECT_EQ(last_depth, 0);
            EXPECT_LE(remembered, 2 * 64);
        }
        EXPECT_LE(max_diff(u, plain), 0.003 * max_abs(plain) + 2 * step_error);
    }
}

// The trapezoidal rule on a stiff nonlinear case at a large step (a
// stiff bar released from a 90-degree twist, dt far above its periods)
// goes unstable; the energy guard stops it with a message that names the
// growth and the remedy, while BDF2 runs through.
TEST(Integrators, EnergyGuardCatchesTrapezoidalBlowUp) {
    auto twisted = [](Integrator integ) {
        Scene s = test::clamped_box_scene(10, 2, 2, 1e6);
        s.gravity = {0, 0, 0};
        s.integrator = integ;
        s.dt = 1e-2;
        s.solver.max_energy_growth = 2;
        return s;
    };
    auto twist = [](Simulator<double>& sim) {
        const Mesh& m = sim.scene().mesh;
        double x0 = 1e300, x1 = -1e300;
        for (index_t v = 0; v < m.num_vertices(); ++v) x0 = std::min(x0, m.X[3 * v]), x1 = std::max(x1, m.X[3 * v]);
        auto u = sim.displacement();
        for (index_t v = 0; v < m.num_vertices(); ++v) {
            const double th = 0.5 * M_PI * (m.X[3 * v] - x0) / (x1 - x0), y = m.X[3 * v + 1], z = m.X[3 * v + 2];
            u[3 * v + 1] = std::cos(th) * y - std::sin(th) * z - y;
            u[3 * v + 2] = std::sin(th) * y + std::cos(th) * z - z;
        }
    };
    std::string message;
    {
        Simulator<double> sim(twisted(Integrator::Newmark));
        twist(sim);
        try {
            for (int k = 0; k < 200; ++k) sim.step();
        } catch (const SimulationError& e) {
            message = e.what();
        }
    }
    std::printf("newmark: %s\n", message.c_str());
    EXPECT_NE(message.find("energy grew without a source"), std::string::npos) << message;
    // The advice is the trapezoidal rule's remedy: numerical damping.
    EXPECT_NE(message.find("use bdf2 or generalized-alpha"), std::string::npos) << message;
    EXPECT_EQ(message.find("use an implicit integrator"), std::string::npos) << message;
    for (Integrator integ : {Integrator::Bdf2, Integrator::Bdf2Linear}) {
        SCOPED_TRACE(to_string(integ));
        Simulator<double> sim(twisted(integ));
        twist(sim);
        EXPECT_NO_THROW(for (int k = 0; k < 200; ++k) sim.step());
    }
}

// The stress suite's nearly incompressible bar (6x2x2 cm, Y = 1e5 Pa, nu =
// 0.499, alpha = 10 /s, released from a bend, dt = 1 ms, the guard at 2):
// generalized-alpha by Newton at the default rho_inf 0.8 is unstable there
// and, without step halvings, the guard stops it, naming the remedy; at
// rho_inf 0.5, the remedy, it runs to rest with 3 halvings allowed
// (bench/rho_inf_study.py, docs/lab/2026-11-28-rho-inf-incompressible.md).
TEST(Integrators, GeneralizedAlphaOnANearlyIncompressibleBarNamesItsRemedy) {
    auto bar = [](double rho_inf, int halvings) {
        return std::make_unique<Simulator<double>>(
            test::bent_incompressible_bar(Integrator::GeneralizedAlpha, rho_inf, halvings));
    };
    std::string message;
    try {
        auto sim = bar(0.8, 0);
        for (int k = 0; k < 500; ++k) sim->step();
    } catch (const SimulationError& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("energy grew without a source"), std::string::npos) << message;
    EXPECT_NE(message.find("lower generalized_alpha.rho_inf"), std::string::npos) << message;
    auto sim = bar(0.5, 3);
    double umax = 0;
    ASSERT_NO_THROW(for (int k = 0; k < 2000; ++k) sim->step());
    for (double x : sim->displacement()) umax = std::max(umax, std::abs(x));
    EXPECT_LT(umax, 1e-5 * 0.06) << "at rest within 1e-5 of the bar's length after 2 s";
}

// The same bar under the linearised generalized-alpha at rho_inf 0.8 and
// dt = 1 ms, 3 step halvings: unstable at 1 ms, stable at 0.5 ms, and its
// instability grows for tens to hundreds of steps before the guard sees it.
// Halving only the failed step, every step went back to 1 ms and the bar
// never settled (0.5-2.9 % of its size after 2 s, 61-87 halvings). With the
// halving remembered (step_control.hpp) the steps stay halved until the
// bar has nearly settled (520 steps) and it comes to rest: 2.9e-7 m
// (4e-6 of its size) after 2 s, 2 halvings.
TEST(Integrators, RememberedHalvingSettlesAnUnstableLinearisedStep) {
    Simulator<double> sim(test::bent_incompressible_bar(Integrator::GeneralizedAlphaLinear, 0.8, 3));
    const double length = 0.06;
    int halvings = 0, halved = 0;
    for (int k = 0; k < 2000; ++k) {
        const StepStats& st = sim.step();
        halvings += st.halvings;
        if (st.substep_depth > 0) ++halved;
    }
    double umax = 0;
    for (double x : sim.displacement()) umax = std::max(umax, std::abs(x));
    std::printf("%d halvings, %d of 2000 steps halved, max |u| %.3g m\n", halvings, halved, umax);
    EXPECT_LT(umax, 1e-5 * length) << "at rest within 1e-5 of the bar's length after 2 s";
    EXPECT_LE(halvings, 8);
    EXPECT_GE(halved, 100);  // it stayed at the stable step
}

// The energy guard's account of mass damping (TimeIntegrator::
// damping_account) adds no spurious gain: in the linear regime (a 1e-6 m/s
// random kick) with alpha = 10 /s and modes the step does not resolve, no
// integrator's largest growth by the guard's count exceeds its undamped
// run's (the scheme's own energy behaviour: generalized-alpha's first-step
// overshoot, symplectic Euler's and Verlet's bounded oscillation) by more
// than 1e-3. Newmark counted as the Euler steps are (2 T alpha x the new
// kinetic energy) was credited with damping modes whose velocity flips
// every step, which the trapezoidal rule barely damps: its largest growth
// was 1.64 here against 1 + 3e-8 undamped; counted as alpha |du|_M^2 / T
// it is 1 + 2e-8. (Generalized-alpha, counted as the Euler steps, is 2e-4
// over its undamped run.)
TEST(Integrators, EnergyGuardCountsEachIntegratorsDamping) {
    struct Run {
        Integrator integ;
        double dt;
    };
    for (const Run& r : {Run{Integrator::Newmark, 1e-3}, Run{Integrator::NewmarkLinear, 1e-3},
                         Run{Integrator::GeneralizedAlpha, 1e-3}, Run{Integrator::GeneralizedAlphaLinear, 1e-3},
                         Run{Integrator::Bdf2, 1e-3}, Run{Integrator::Bdf2Linear, 1e-3},
                         Run{Integrator::Implicit, 1e-3}, Run{Integrator::SemiImplicit, 1e-3},
                         Run{Integrator::Explicit, 2e-5}, Run{Integrator::Verlet, 2e-5}}) {
        SCOPED_TRACE(to_string(r.integ));
        double growth[2] = {0, 0};
        for (int damped = 0; damped < 2; ++damped) {
            Scene s = test::clamped_box_scene(6, 2, 2, 1e5);
            s.gravity = {0, 0, 0};
            s.rayleigh_alpha = damped ? 10 : 0;
            s.integrator = r.integ;
            s.dt = r.dt;
            s.solver.cg_tolerance = 1e-10;
            s.solver.max_energy_growth = 1e9;  // measured, never failed
            Simulator<double> sim(s);
            auto v = sim.velocity();
            for (std::size_t i = 0; i < v.size(); ++i) v[i] = 1e-6 * std::sin(12.9898 * double(i) + 78.233);
            for (index_t f : sim.scene().fixed)
                for (int c = 0; c < 3; ++c) v[3 * std::size_t(f) + c] = 0;
            for (int k = 0; k < 300; ++k) growth[damped] = std::max(growth[damped], sim.step().energy_growth);
        }
        std::printf("%s: largest energy_growth %.9f undamped, %.9f with alpha = 10 /s\n", to_string(r.integ),
                    growth[0], growth[1]);
        EXPECT_LE(growth[1], growth[0] + 1e-3);
    }
}

// A beam shaken at one end (its x = min face moved 20 mm in z over 0.1 s,
// a smooth ramp) with stiffness damping beta = 1e-3 s: the moving face
// drags the body through the damping force -beta K_fc v_c, a source the
// energy guard must count as it counts the constraints' elastic work.
// Before it did, the trapezoidal rule's steps failed in the first 0.01 s
// (here in step 5, +10.4x: a gain counted against the small energy of a
// motion just begun; 71x with the guard off on a beam twice as long) while
// the trajectory is within 1 % of a fine generalized-alpha run, as it is
// here.
TEST(Integrators, EnergyGuardCountsTheDragOfMovingConstraintsThroughDamping) {
    const auto shaken = [](Integrator integ, double dt) {
        Scene s;
        s.mesh = make_box(24, 3, 3, 0.005);
        s.materials = Material{1e6, 0.45, 1000};
        s.rayleigh_beta = 1e-3;
        double x0 = 1e300;
        for (index_t v = 0; v < s.mesh.num_vertices(); ++v) x0 = std::min(x0, s.mesh.X[3 * v]);
        for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
            if (s.mesh.X[3 * v] < x0 + 1e-9)
                s.prescribed.push_back({v, {s.mesh.X[3 * v], s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2] + 0.02}});
        for (int k = 0; k <= 20; ++k) s.prescribed_keyframes.push_back({0.1 * k / 20, 0.5 * (1 - std::cos(M_PI * k / 20))});
        s.integrator = integ;
        s.dt = dt;
        s.solver.cg_tolerance = 1e-8;
        s.solver.cg_max_iterations = 2000;
        s.solver.newton_tolerance = 1e-10;
        return s;
    };
    const double t_end = 0.06;
    const std::vector<double> ref = run_to(shaken(Integrator::GeneralizedAlpha, 2e-4), t_end);
    for (Integrator integ : {Integrator::NewmarkLinear, Integrator::Newmark}) {
        SCOPED_TRACE(to_string(integ));
        Simulator<double> sim(shaken(integ, 2e-3));
        double growth = 0;
        for (int k = 0; k < 30; ++k) growth = std::max(growth, sim.step().energy_growth);
        const std::vector<double> u(sim.displacement().begin(), sim.displacement().end());
        const double error = max_diff(u, ref) / max_abs(ref);
        std::printf("%s: largest energy_growth %.4f, error %.2e\n", to_string(integ), growth, error);
        EXPECT_LE(growth, 1.5);
        EXPECT_LE(error, 0.01);
    }
}

// The semi-implicit step's CG starts from v moved along the change of
// velocity over the last step, by the alpha that lowers the A-norm error
// most (CgSolver's improve_start). Each step is solved again by a new
// simulator given only u and v (no history: CG from v): the same step to
// the same tolerance, so the velocities agree to CG's accuracy (1.4e-6
// here), in at least 15 % fewer block-Jacobi iterations (24 %: 489 against
// 644, 2026-11-28; without the warm start the counts are equal). With a
// fixed CG budget there is no warm start (its cost is the budget): the
// steps are the same bits.
TEST(Integrators, SemiImplicitWarmStartAlongTheVelocityChange) {
    Scene s = test::clamped_box_scene(24, 3, 3, 1e5);
    s.integrator = Integrator::SemiImplicit;
    s.dt = 1e-3;
    s.solver.preconditioner = PreconditionerKind::BlockJacobi;
    for (const int budget : {0, 8}) {
        s.solver.cg_fixed_iterations = budget;
        Simulator<double> sim(s);
        long warm = 0, cold = 0;
        double worst = 0;
        bool same_bits = true;
        for (int k = 0; k < 40; ++k) {
            Simulator<double> fresh(s);
            std::ranges::copy(sim.displacement(), fresh.displacement().begin());
            std::ranges::copy(sim.velocity(), fresh.velocity().begin());
            const int cold_its = fresh.step().solver_iterations, warm_its = sim.step().solver_iterations;
            if (k >= 2) {
                warm += warm_its;
                cold += cold_its;
            }
            const auto v = sim.velocity(), w = fresh.velocity();
            const std::vector<double> a(v.begin(), v.end()), b(w.begin(), w.end());
            worst = std::max(worst, max_diff(a, b) / max_abs(a));
            same_bits = same_bits && a == b;
        }
        if (budget > 0) {
            EXPECT_TRUE(same_bits) << "a fixed CG budget has no warm start";
            continue;
        }
        std::printf("warm start: %ld against %ld CG iterations; velocities within %.2g\n", warm, cold, worst);
        EXPECT_LE(20 * warm, 17 * cold);
        EXPECT_LT(worst, 1e-5);
    }
}

// The linearised integrators' CG to a tolerance starts from the step's
// prediction moved along a direction from the last step
// (solver.warm_start): the acceleration (newmark-linear,
// generalized-alpha-linear) or the change of velocity (bdf2-linear). The
// same steps to the same tolerance, so the displacements agree to CG's
// accuracy (1e-6 of the largest; CG to 1e-9; 4e-9 to 6e-9 seen), in at
// least 5 % fewer block-Jacobi iterations (2026-11-28: 9-12 % on this beam
// with beta; with the direction not applied the counts are equal).
TEST(Integrators, LinearisedSecondOrderWarmStart) {
    for (Integrator integ : {Integrator::NewmarkLinear, Integrator::GeneralizedAlphaLinear, Integrator::Bdf2Linear}) {
        SCOPED_TRACE(to_string(integ));
        Scene s = test::clamped_box_scene(24, 3, 3, 1e5);
        s.integrator = integ;
        s.dt = 2e-3;
        s.rayleigh_beta = 1e-3;
        s.solver.preconditioner = PreconditionerKind::BlockJacobi;
        s.solver.cg_tolerance = 1e-9;
        Scene cold_scene = s;
        cold_scene.solver.warm_start = false;
        Simulator<double> warm(s), cold(cold_scene);
        long warm_its = 0, cold_its = 0;
        for (int k = 0; k < 40; ++k) {
            warm_its += warm.step().solver_iterations;
            cold_its += cold.step().solver_iterations;
        }
        const std::vector<double> a(warm.displacement().begin(), warm.displacement().end()),
            b(cold.displacement().begin(), cold.displacement().end());
        const double diff = max_diff(a, b) / max_abs(b);
        std::printf("%s: warm start %ld against %ld CG iterations; displacements within %.2g\n", to_string(integ),
                    warm_its, cold_its, diff);
        EXPECT_LE(100 * warm_its, 95 * cold_its);
        EXPECT_LT(diff, 1e-6);
    }
}

// In the linear regime (the tip moves 1e-6 of the length) one Newton
// iteration from the step's start solves the step: each linearised
// integrator follows its Newton form within 1e-6 of the largest
// displacement, with Rayleigh damping (alpha and beta) too. The linearised
// step applies beta's K0 folded into K (both built at the step's start);
// with beta's share 1.5x in the solve the pairs part by 1.4e-2 to 2.4e-2
// (3e-9 to 6e-9 seen as it is).
TEST(Integrators, LinearisedStepsAreTheirNewtonFormsInTheLinearRegime) {
    const std::pair<Integrator, Integrator> pairs[] = {{Integrator::SemiImplicit, Integrator::Implicit},
                                                       {Integrator::NewmarkLinear, Integrator::Newmark},
                                                       {Integrator::GeneralizedAlphaLinear, Integrator::GeneralizedAlpha},
                                                       {Integrator::Bdf2Linear, Integrator::Bdf2}};
    for (const auto& [linear, newton] : pairs) {
        SCOPED_TRACE(to_string(linear));
        auto scene = [](Integrator integ) {
            Scene s = linear_swing(integ, 2e-3);
            s.gravity = {0, 0, -2e-4};
            s.rayleigh_alpha = 0.5;
            s.rayleigh_beta = 1e-3;
            return s;
        };
        const std::vector<double> a = run_to(scene(linear), 0.08), b = run_to(scene(newton), 0.08);
        const double diff = max_diff(a, b) / max_abs(b);
        std::printf("%s against %s: %.2g of the largest displacement\n", to_string(linear), to_string(newton), diff);
        EXPECT_LT(diff, 1e-6);
    }
}

// Float models run every new integrator and track double.
TEST(Integrators, FloatTracksDouble) {
    for (Integrator integ : kSecondOrder) {
        SCOPED_TRACE(to_string(integ));
        Scene s = swing(integ, integ == Integrator::Verlet ? 1e-4 : 2e-3);
        s.solver.newton_tolerance = 1e-10;
        s.solver.cg_tolerance = 1e-6;
        const int n = int(std::lround(0.1 / s.dt));
        Simulator<double> d(s);
        Simulator<float> f(s);
        for (int k = 0; k < n; ++k) {
            d.step();
            f.step();
        }
        double diff = 0, ref = 0;
        for (std::size_t i = 0; i < d.displacement().size(); ++i) {
            diff = std::max(diff, std::abs(double(f.displacement()[i]) - d.displacement()[i]));
            ref = std::max(ref, std::abs(d.displacement()[i]));
        }
        EXPECT_LE(diff, 1e-3 * ref);
    }
}

// Bad parameters are errors that name the key.
TEST(Integrators, BadParametersNameTheKey) {
    auto rejected = [](Scene s, const std::string& key) {
        try {
            s.validate();
            ADD_FAILURE() << "accepted: " << key;
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    };
    Scene s = swing(Integrator::Newmark, 1e-3);
    s.integrator_parameters.newmark_beta = 0.6;
    rejected(s, "newmark.beta");
    s = swing(Integrator::Newmark, 1e-3);
    s.integrator_parameters.newmark_gamma = 0.4;
    rejected(s, "newmark.gamma");
    s = swing(Integrator::GeneralizedAlpha, 1e-3);
    s.integrator_parameters.rho_inf = 1.5;
    rejected(s, "generalized_alpha.rho_inf");
    s = swing(Integrator::Verlet, 1e-3);
    s.rayleigh_beta = 0.01;
    rejected(s, "damping.beta");
    s = swing(Integrator::Bdf2, 1e-3);
    s.solver.cg_fixed_iterations = 10;
    rejected(s, "solver.cg_fixed_iterations");
    s.integrator = Integrator::Bdf2Linear;
    EXPECT_NO_THROW(s.validate());
    s.integrator = static_cast<Integrator>(99);
    rejected(s, "integrator");
}

// The scene's initial state, keyframed prescribed motion and loads.
TEST(Integrators, InitialStateKeyframesAndLoads) {
    // A free body given a uniform velocity translates rigidly: u(t) = v t
    // with every integrator (no forces arise).
    for (const auto& [name, integ] : integrator_names()) {
        SCOPED_TRACE(name);
        Scene s = swing(integ, 1e-3);
        s.fixed.clear();
        s.gravity = {0, 0, 0};
        s.initial_velocity.assign(s.mesh.X.size(), 0.0);
        for (std::size_t i = 0; i < s.initial_velocity.size(); i += 3) s.initial_velocity[i] = 0.1;
        const std::vector<double> u = run_to(s, 0.05);
        for (std::size_t i = 0; i < u.size(); ++i) ASSERT_NEAR(u[i], i % 3 == 0 ? 0.005 : 0.0, 1e-12) << i;
    }
    // A prescribed vertex follows its keyframes: at t = 0.02 s (value 1)
    // it is at its target, at t = 0.04 s (value 0.5) halfway back.
    Scene p = swing(Integrator::Bdf2, 1e-3);
    const index_t tip = p.mesh.num_vertices() - 1;
    p.prescribed.push_back({tip, {p.mesh.X[3 * tip] + 0.004, p.mesh.X[3 * tip + 1], p.mesh.X[3 * tip + 2]}});
    p.prescribed_keyframes = {{0, 0}, {0.02, 1}, {0.04, 0.5}};
    EXPECT_NEAR(run_to(p, 0.02)[3 * tip], 0.004, 1e-15);
    EXPECT_NEAR(run_to(p, 0.04)[3 * tip], 0.002, 1e-15);
    // A constant scene load is the application's external force: the
    // same trajectory, bitwise; keyframed to zero after 0.05 s, the
    // energy guard (which counts its work) lets it through.
    Scene a = swing(Integrator::Newmark, 1e-3);
    a.load.assign(a.mesh.X.size(), 0.0);
    a.load.back() = -0.01;
    Scene b = a;
    b.load.clear();
    const std::vector<double> ua = run_to(a, 0.05);
    Simulator<double> sb(b);
    sb.external_forces().back() = -0.01;
    for (int k = 0; k < 50; ++k) sb.step();
    EXPECT_TRUE(std::equal(ua.begin(), ua.end(), sb.displacement().begin()));
    a.load_keyframes = {{0, 1}, {0.05, 1}, {0.06, 0}};
    EXPECT_NO_THROW(run_to(a, 0.2));
}
