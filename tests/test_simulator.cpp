// Dynamics and statics: conservation laws, convergence orders, equilibrium,
// the definite tangent, and clear failures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/core/cg.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "cantilever.hpp"
#include "forwarding_operator.hpp"
#include "models.hpp"

using namespace edgefem;

namespace {

Scene cantilever(Integrator integrator, double dt) { return test::cantilever_scene(integrator, dt); }

// The SimulationError that stepping `s` at most `steps` times ends in (its
// message and vertex; a test failure when none comes).
std::pair<std::string, index_t> step_failure(Scene s, int steps) {
    Simulator<double> sim(std::move(s));
    try {
        for (int k = 0; k < steps; ++k) sim.step();
    } catch (const SimulationError& e) {
        return {e.what(), e.vertex()};
    }
    ADD_FAILURE() << "no error in " << steps << " steps";
    return {"", -1};
}

// Constructing a Simulator on `s` throws E, its message containing `what`.
template <class E>
void expect_rejected(Scene s, const std::string& what) {
    try {
        Simulator<double> sim(std::move(s));
        ADD_FAILURE() << "accepted: " << what;
    } catch (const E& e) {
        EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
}

double total_mass(const Simulator<double>& sim) {
    double m = 0;
    for (double x : sim.lumped_mass()) m += x;
    return m;
}

std::vector<double> momentum(Simulator<double>& sim) {
    std::vector<double> p(3, 0.0);
    const auto v = sim.velocity();
    const auto m = sim.lumped_mass();
    for (std::size_t i = 0; i < v.size(); ++i) p[i % 3] += m[i / 3] * v[i];
    return p;
}

}  // namespace

TEST(Simulator, ExplicitSwingConservesEnergyWithinBound) {
    Simulator<double> sim(cantilever(Integrator::Explicit, 2e-5));
    const double E0 = sim.energies().total();
    // Energy scale: the gravity potential released if the beam dropped 1 cm.
    const double scale = total_mass(sim) * 9.81 * 0.01;
    double worst = 0;
    for (int k = 0; k < 5000; ++k) {  // 0.1 s: a good part of a swing
        sim.step();
        if (k % 100 == 99) worst = std::max(worst, std::abs(sim.energies().total() - E0));
    }
    EXPECT_GT(sim.energies().kinetic, 0);
    // Symplectic Euler: bounded oscillation, O(dt), no drift.
    EXPECT_LT(worst, 0.02 * scale);
}

TEST(Simulator, ImplicitSchemesDissipateAndNeverGainEnergy) {
    for (Integrator integ : {Integrator::SemiImplicit, Integrator::Implicit}) {
        SCOPED_TRACE(to_string(integ));
        Simulator<double> sim(cantilever(integ, 2e-3));
        double prev = sim.energies().total();
        const double scale = total_mass(sim) * 9.81 * 0.01;
        for (int k = 0; k < 50; ++k) {
            sim.step();
            const double E = sim.energies().total();
            EXPECT_LE(E, prev + 1e-6 * scale) << "step " << k;  // backward Euler is dissipative
            prev = E;
        }
    }
}

TEST(Simulator, MomentumConservedWithoutGravityOrSupports) {
    for (Integrator integ : {Integrator::Explicit, Integrator::SemiImplicit, Integrator::Implicit}) {
        SCOPED_TRACE(to_string(integ));
        Scene s = cantilever(integ, integ == Integrator::Explicit ? 2e-5 : 1e-3);
        s.fixed.clear();
        s.gravity = {0, 0, 0};
        Simulator<double> sim(std::move(s));
        auto v = sim.velocity();
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.05 * std::sin(0.7 * i) + (i % 3 == 0 ? 0.02 : 0.0);
        const auto p0 = momentum(sim);
        double pscale = 0;
        for (std::size_t i = 0; i < v.size(); ++i) pscale += sim.lumped_mass()[i / 3] * std::abs(v[i]);
        for (int k = 0; k < 20; ++k) sim.step();
        const auto p1 = momentum(sim);
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(p1[r], p0[r], 1e-8 * pscale);
    }
}

TEST(Simulator, SemiImplicitConvergesToImplicitAtFirstOrder) {
    const double t_end = 0.04;
    std::vector<double> diffs;
    for (double dt : {4e-3, 2e-3, 1e-3}) {
        Simulator<double> semi(cantilever(Integrator::SemiImplicit, dt));
        Simulator<double> impl(cantilever(Integrator::Implicit, dt));
        const int n = int(std::lround(t_end / dt));
        for (int k = 0; k < n; ++k) {
            semi.step();
            impl.step();
        }
        double d = 0, ref = 0;
        for (std::size_t i = 0; i < semi.displacement().size(); ++i) {
            d = std::max(d, std::abs(semi.displacement()[i] - impl.displacement()[i]));
            ref = std::max(ref, std::abs(impl.displacement()[i]));
        }
        diffs.push_back(d / ref);
    }
    // Each halving of dt roughly halves the gap (first order).
    EXPECT_GT(diffs[0] / diffs[1], 1.6);
    EXPECT_GT(diffs[1] / diffs[2], 1.6);
    EXPECT_LT(diffs[2], 0.05);
}

TEST(Simulator, StaticEquilibriumResidualAndReactionsEqualWeight) {
    for (LinearSolver ls : {LinearSolver::CG, LinearSolver::Direct}) {
        SCOPED_TRACE(to_string(ls));
        Scene s = cantilever(Integrator::Implicit, 1e-3);
        s.solver.linear_solver = ls;
        s.solver.newton_tolerance = 1e-11;
        const std::vector<index_t> fixed = s.fixed;
        Simulator<double> sim(std::move(s));
        const StaticResult r = sim.solve_static();
        EXPECT_TRUE(r.converged);
        EXPECT_GT(r.newton_iterations, 0);
        // Independent check of equilibrium: f - M g vanishes on free vertices.
        const auto f = sim.forces();
        const auto m = sim.lumped_mass();
        std::vector<char> is_fixed(sim.num_vertices(), 0);
        for (index_t v : fixed) is_fixed[v] = 1;
        double res = 0, scale = 0, reaction_z = 0;
        for (std::size_t i = 0; i < f.size(); ++i) {
            const double h = (i % 3 == 2) ? -9.81 * m[i / 3] : 0.0;
            scale += f[i] * f[i];
            if (!is_fixed[i / 3])
                res += (f[i] - h) * (f[i] - h);
            else if (i % 3 == 2)
                reaction_z += f[i] - h;  // support force on the beam: f = h + reaction
        }
        EXPECT_LE(std::sqrt(res), 1e-10 * std::sqrt(scale));
        // Supports carry the whole weight (vertical reactions sum to m g).
        EXPECT_NEAR(reaction_z, 9.81 * total_mass(sim), 1e-8 * 9.81 * total_mass(sim));
        // The beam sags.
        double min_uz = 0;
        for (std::size_t i = 2; i < f.size(); i += 3) min_uz = std::min(min_uz, sim.displacement()[i]);
        EXPECT_LT(min_uz, -1e-4);
    }
}

TEST(Simulator, DefiniteTangentKeepsCgConvergentOnCompressedCube) {
    const Mesh mesh = make_box(4, 4, 4);
    auto plain = make_cpu_operator<double>(mesh, Material{1e5, 0.3, 1000}, ModelKind::FE, Method::Edge);
    // Compress to 20% of the height, with a small shear so the state is generic.
    std::vector<double> u(mesh.X.size());
    for (index_t v = 0; v < mesh.num_vertices(); ++v) {
        u[3 * v + 2] = -0.8 * (mesh.X[3 * v + 2] + 0.02);
        u[3 * v] = 0.05 * mesh.X[3 * v + 2];
    }
    std::vector<double> f(u.size());
    plain->forces(u.data(), f.data(), false);
    std::vector<std::uint8_t> free_dof(u.size(), 1);
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.X[3 * v + 2] < -0.02 + 1e-9) free_dof[3 * v] = free_dof[3 * v + 1] = free_dof[3 * v + 2] = 0;
    std::vector<double> b(u.size());
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = std::cos(0.3 * i);
    // (identity preconditioner: z = r)
    auto run_id = [&](bool definite) {
        plain->build_stiffness(definite);
        std::vector<double> x(u.size(), 0.0);
        CgWork w;
        const std::size_t n = u.size();
        return conjugate_gradient(
            SerialExecutor{}, n, free_dof.data(), [&](const double* in, double* out) { plain->multiply(in, out); },
            [](std::size_t, std::size_t, const double*, double*) {},
            [](std::size_t lo, std::size_t hi, const double* r, double* z) { std::copy(r + lo, r + hi, z + lo); },
            b.data(), x.data(), 1e-8, 5000, 0, w);
    };
    const CgResult p = run_id(false), d = run_id(true);
    EXPECT_TRUE(p.negative_curvature);
    EXPECT_FALSE(p.converged);
    EXPECT_FALSE(d.negative_curvature);
    EXPECT_TRUE(d.converged);

    // Inside the simulator the plain K's failure is detected and handled: a
    // big step from the compressed state stays finite and reports it.
    Scene s;
    s.mesh = mesh;
    s.materials = Material{1e5, 0.3, 1000};
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.X[3 * v + 2] < -0.02 + 1e-9) s.fixed.push_back(v);
    s.dt = 0.05;
    // That step multiplies the energy by ~30 (a linearised step this large
    // from a compressed state is no physics): the energy guard rejects it...
    {
        Simulator<double> guarded(s);
        std::copy(u.begin(), u.end(), guarded.displacement().begin());
        for (index_t v : s.fixed)
            for (int r = 0; r < 3; ++r) guarded.displacement()[3 * v + r] = 0;
        try {
            guarded.step();
            ADD_FAILURE() << "the energy guard let a 30x energy gain through";
        } catch (const SimulationError& e) {
            EXPECT_NE(std::string(e.what()).find("step 1: energy grew without a source"), std::string::npos) << e.what();
        }
    }
    // ...so the negative-curvature handling is checked with it off: with
    // block-Jacobi CG, and with an AMG whose one level is the whole system
    // (its dense LDL^T solves A exactly, so CG cannot meet the negative
    // curvature itself: p.Ap = r.A^-1 r > 0; the set-up's negative pivot
    // reports it).
    s.solver.max_energy_growth = 0;
    Scene amg_scene = s;
    amg_scene.solver.preconditioner = PreconditionerKind::Amg;
    amg_scene.solver.amg.max_coarse_dofs = 1000;
    Scene amg_every_5 = amg_scene;  // refreshed every 5th K: the fallback's K is refreshed all the same
    amg_every_5.solver.amg_refresh_interval = 5;
    for (const Scene& scene : {s, amg_scene, amg_every_5}) {
        SCOPED_TRACE(std::string(to_string(scene.solver.preconditioner)) + ", refresh interval " +
                     std::to_string(scene.solver.amg_refresh_interval));
        Simulator<double> sim(scene);
        std::copy(u.begin(), u.end(), sim.displacement().begin());
        for (index_t v : scene.fixed)
            for (int r = 0; r < 3; ++r) sim.displacement()[3 * v + r] = 0;
        const StepStats& st = sim.step();
        EXPECT_TRUE(st.negative_curvature);
        for (double x : sim.displacement()) ASSERT_TRUE(std::isfinite(x));
    }
}

TEST(Simulator, ExplicitBlowUpIsAClearError) {
    Scene s = cantilever(Integrator::Explicit, 5e-2);  // far beyond the stable step
    s.materials = Material{1e7, 0.3, 1000};
    Simulator<double> sim(std::move(s));
    try {
        for (int k = 0; k < 1000; ++k) sim.step();
        FAIL() << "no error";
    } catch (const SimulationError& e) {
        EXPECT_GT(e.step(), 0);
        EXPECT_GE(e.vertex(), 0);
        const std::string msg = e.what();
        EXPECT_NE(msg.find("step " + std::to_string(e.step())), std::string::npos) << msg;
        EXPECT_NE(msg.find("vertex " + std::to_string(e.vertex())), std::string::npos) << msg;
    }
}

TEST(Simulator, StepHalvingRecoversWhereAPlainStepFails) {
    Scene s = cantilever(Integrator::Implicit, 5e-2);
    s.solver.newton_max_iterations = 3;
    Simulator<double> plain(s);
    EXPECT_THROW(plain.step(), SimulationError);
    s.solver.max_step_halvings = 6;
    Simulator<double> halving(s);
    const StepStats& st = halving.step();
    EXPECT_GT(st.halvings, 0);
    EXPECT_NEAR(halving.time(), 5e-2, 1e-15);
}

TEST(Simulator, FloatTracksDoubleAndSceneErrorsNameTheField) {
    Simulator<double> d(cantilever(Integrator::SemiImplicit, 1e-3));
    Simulator<float> f(cantilever(Integrator::SemiImplicit, 1e-3));
    for (int k = 0; k < 20; ++k) {
        d.step();
        f.step();
    }
    double diff = 0, ref = 0;
    for (std::size_t i = 0; i < d.displacement().size(); ++i) {
        diff = std::max(diff, std::abs(d.displacement()[i] - double(f.displacement()[i])));
        ref = std::max(ref, std::abs(d.displacement()[i]));
    }
    EXPECT_LT(diff, 1e-4 * ref);

    const auto expect_field = expect_rejected<InvalidArgument>;
    Scene s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.dt = -1;
    expect_field(s, "\"dt\"");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.fixed.push_back(100000);
    expect_field(s, "fixed[");
    s = cantilever(Integrator::Verlet, 1e-3);
    s.rayleigh_beta = 0.1;
    expect_field(s, "damping.beta");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.solver.cg_tolerance = 0;
    expect_field(s, "solver.cg_tolerance");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.solver.max_step_halvings = 31;  // a step in 2^31 pieces
    expect_field(s, "solver.max_step_halvings");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.method = Method::Tet;
    s.model = ModelKind::SN;
    expect_field(s, "model");
}

namespace {

// Core's operator, counting build_stiffness calls.
class CountingOperator final : public test::ForwardingOperator {
public:
    CountingOperator(std::unique_ptr<ElasticOperator<double>> op, int& builds)
        : ForwardingOperator(std::move(op)), builds_(builds) {}
    void build_stiffness(bool definite) override {
        ++builds_;
        op_->build_stiffness(definite);
    }

private:
    int& builds_;
};

OperatorFactory<double> counting_factory(int& builds) {
    return [&builds](const Mesh& m, const Materials& mat, ModelKind k, Method me) -> std::unique_ptr<ElasticOperator<double>> {
        return std::make_unique<CountingOperator>(make_cpu_operator<double>(m, mat, k, me), builds);
    };
}

}  // namespace

// A lagged tangent: K rebuilt every N semi-implicit steps. It builds K less
// often (counted), stays close to the every-step trajectory on a
// gentle swing, and the scene validates the interval.
TEST(Simulator, StiffnessIntervalReusesKAndStaysClose) {
    Scene every = cantilever(Integrator::SemiImplicit, 1e-3);
    Scene lagged = every;
    lagged.solver.stiffness_interval = 4;
    int a_builds = 0, b_builds = 0;
    Simulator<double> a(every, nullptr, counting_factory(a_builds)), b(lagged, nullptr, counting_factory(b_builds));
    for (int k = 0; k < 40; ++k) {
        a.step();
        b.step();
    }
    EXPECT_EQ(a_builds, 40);
    EXPECT_EQ(b_builds, 10);
    double diff = 0, ref = 0;
    for (std::size_t i = 0; i < a.displacement().size(); ++i) {
        diff = std::max(diff, std::abs(a.displacement()[i] - b.displacement()[i]));
        ref = std::max(ref, std::abs(a.displacement()[i]));
    }
    EXPECT_LT(diff, 0.05 * ref);
    EXPECT_GT(diff, 0.0);  // it really is a different linearisation
    lagged.solver.stiffness_interval = 0;
    EXPECT_THROW(Simulator<double>{lagged}, InvalidArgument);
}

// With stiffness damping a linearised step's damping tangent K0 is its K
// (both at the step's start): one K built per step, for every linearised
// integrator (a second operator built K0 as well until 2026-11-28). The
// Newton forms build K0 and a K per Newton iteration.
TEST(Simulator, LinearisedStepsWithStiffnessDampingBuildOneK) {
    for (Integrator integ : {Integrator::SemiImplicit, Integrator::NewmarkLinear, Integrator::GeneralizedAlphaLinear,
                             Integrator::Bdf2Linear, Integrator::Newmark}) {
        SCOPED_TRACE(to_string(integ));
        Scene s = cantilever(integ, 2e-3);
        s.rayleigh_beta = 1e-3;
        int builds = 0;
        Simulator<double> sim(s, nullptr, counting_factory(builds));
        long newton_iterations = 0;
        for (int k = 0; k < 10; ++k) newton_iterations += sim.step().newton_iterations;
        if (integ == Integrator::Newmark)
            EXPECT_EQ(builds, 10 + newton_iterations);
        else
            EXPECT_EQ(builds, 10);
    }
}

// A CG solve cut off by its iteration cap is never silent: an error naming
// the step (the default), or counted in the step's statistics when the scene
// opts out.
TEST(Simulator, UnconvergedSolvesAreCountedOrFatal) {
    Scene s = cantilever(Integrator::SemiImplicit, 1e-2);
    s.materials = Material{1e8, 0.3, 1000};  // stiff: many iterations needed
    s.solver.cg_tolerance = 1e-10;
    s.solver.cg_max_iterations = 3;
    s.solver.fail_on_unconverged = false;
    Simulator<double> counted(s);
    EXPECT_GT(counted.step().unconverged_solves, 0);
    s.solver.fail_on_unconverged = true;  // the default
    EXPECT_TRUE(Scene{}.solver.fail_on_unconverged);
    Simulator<double> strict(s);
    try {
        strict.step();
        FAIL() << "no error";
    } catch (const SimulationError& e) {
        EXPECT_NE(std::string(e.what()).find("step 1: CG stopped at 3 iterations"), std::string::npos) << e.what();
    }
    s.solver.cg_max_iterations = 5000;  // enough: no count, no error
    Simulator<double> enough(s);
    EXPECT_EQ(enough.step().unconverged_solves, 0);
}

// ---- The energy guard (SolverSettings::max_energy_growth) -----------------

// An explicit step above the stability limit makes the energy grow
// geometrically: the guard stops it with an error naming the step, the
// growth and the fastest vertex while the state is still finite, steps
// before the state turns non-finite (which is what stops it with the guard
// off).
TEST(Simulator, EnergyGuardStopsAnUnstableExplicitRunBeforeItIsNonFinite) {
    Scene s = cantilever(Integrator::Explicit, 4e-3);  // a few times the stable step
    ASSERT_GT(s.solver.max_energy_growth, 0);           // on by default
    auto fail_step = [](Scene sc, std::string& msg) {
        Simulator<double> sim(std::move(sc));
        try {
            for (int k = 0; k < 2000; ++k) sim.step();
        } catch (const SimulationError& e) {
            msg = e.what();
            EXPECT_GE(e.vertex(), 0);
            EXPECT_NE(msg.find("vertex " + std::to_string(e.vertex())), std::string::npos) << msg;
            const bool by_guard = msg.find("energy grew") != std::string::npos;
            for (double x : sim.displacement()) {
                if (by_guard) {
                    EXPECT_TRUE(std::isfinite(x)) << msg;  // caught while the state is still finite
                }
            }
            return e.step();
        }
        ADD_FAILURE() << "no error";
        return 0L;
    };
    std::string guarded, unguarded;
    const long at_guard = fail_step(s, guarded);
    s.solver.max_energy_growth = 0;
    const long at_nan = fail_step(s, unguarded);
    EXPECT_NE(guarded.find("step " + std::to_string(at_guard) + ": energy grew without a source: +"), std::string::npos)
        << guarded;
    EXPECT_NE(guarded.find("over solver.max_energy_growth = 10; fastest vertex "), std::string::npos) << guarded;
    EXPECT_NE(unguarded.find("non-finite"), std::string::npos) << unguarded;
    EXPECT_LT(at_guard, at_nan);
    EXPECT_GT(at_guard, 1);

    // With step halving the guard's failure is retried with smaller steps
    // like any other failed step: the run goes on.
    // (A tight factor: with the default 10 the growth caught is already in
    // the state the halves start from.)
    s.solver.max_energy_growth = 1.5;
    s.solver.max_step_halvings = 4;
    Simulator<double> halving(s);
    int halvings = 0;
    for (int k = 0; k < at_guard + 20; ++k) halvings += halving.step().halvings;
    EXPECT_GT(halvings, 0);
    for (double x : halving.displacement()) ASSERT_TRUE(std::isfinite(x));
}

// Normal runs never trip it: a beam swinging under gravity (explicit at a
// stable step; semi-implicit and implicit with 1% slack: backward Euler is
// (nearly) dissipative), a body pushed by an external
// force from rest (its energy comes from the force's work), a prescribed
// ramp (constraint work: not checked) and velocities the application sets
// between steps (part of the next step's starting energy).
TEST(Simulator, EnergyGuardLetsNormalRunsThrough) {
    {
        Simulator<double> sim(cantilever(Integrator::Explicit, 2e-5));
        for (int k = 0; k < 3000; ++k) ASSERT_NO_THROW(sim.step()) << k;
    }
    for (Integrator integ : {Integrator::SemiImplicit, Integrator::Implicit}) {
        SCOPED_TRACE(to_string(integ));
        Scene s = cantilever(integ, 2e-3);
        // Backward Euler dissipates where W is convex; in this swing's large
        // rotations StVK is not, and the implicit step gains ~0.1% of the
        // swing's energy over 100 steps: 1% slack, far below the default.
        s.solver.max_energy_growth = 1.01;
        Simulator<double> sim(s);
        for (int k = 0; k < 100; ++k) ASSERT_NO_THROW(sim.step()) << k;
        EXPECT_GT(sim.energies().kinetic, 0);
    }
    for (Integrator integ : {Integrator::Explicit, Integrator::SemiImplicit, Integrator::Implicit}) {
        SCOPED_TRACE(to_string(integ));
        Scene s = cantilever(integ, integ == Integrator::Explicit ? 2e-5 : 1e-3);
        s.gravity = {0, 0, 0};
        s.solver.max_energy_growth = integ == Integrator::Explicit ? 1.05 : 1.01;
        Simulator<double> sim(s);
        auto fext = sim.external_forces();
        for (index_t v = 0; v < sim.num_vertices(); ++v)
            if (s.mesh.X[3 * v] > 0.04 - 1e-9) fext[3 * v + 2] = 0.01;  // the free end pulled up
        const int steps = integ == Integrator::Explicit ? 2000 : 40;
        for (int k = 0; k < steps; ++k) ASSERT_NO_THROW(sim.step()) << k;
        EXPECT_GT(sim.energies().kinetic + sim.energies().elastic, 0);
        // The application kicks the body: not the step's doing.
        for (auto& x : sim.velocity()) x += 0.05;
        for (int k = 0; k < 5; ++k) ASSERT_NO_THROW(sim.step()) << k;
    }
    {
        Scene s = cantilever(Integrator::SemiImplicit, 1e-3);
        s.gravity = {0, 0, 0};
        s.solver.max_energy_growth = 1.01;
        for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
            if (s.mesh.X[3 * v] > 0.04 - 1e-9)
                s.prescribed.push_back({v, {s.mesh.X[3 * v], s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2] + 0.01}});
        s.prescribed_steps = 20;
        Simulator<double> sim(s);
        for (int k = 0; k < 60; ++k) ASSERT_NO_THROW(sim.step()) << k;
        EXPECT_GT(sim.energies().elastic, 0);
    }
}

// A fixed CG budget (a haptic loop's partial solve) is not dissipative: the
// guard measures it (StepStats::energy_growth) but never fails it, as
// fail_on_unconverged never does.
TEST(Simulator, EnergyGuardMeasuresButNeverFailsAFixedCgBudget) {
    Scene s = cantilever(Integrator::SemiImplicit, 2e-3);
    s.solver.cg_fixed_iterations = 1;
    s.solver.max_energy_growth = 1;  // no slack at all
    Simulator<double> sim(s);
    double most = 0;
    for (int k = 0; k < 200; ++k) {
        const StepStats& st = sim.step();
        EXPECT_GE(st.energy_growth, 1.0) << k;
        most = std::max(most, st.energy_growth);
    }
    EXPECT_GT(most, 1.0);  // it did gain energy: an unchecked partial solve would have failed
    s.solver.cg_fixed_iterations = 0;
    s.solver.max_energy_growth = 0;
    Simulator<double> off(s);
    EXPECT_EQ(off.step().energy_growth, 0);  // guard off: not measured
}

namespace {

// A 0.24 m beam of 5 mm cells (Y = 1e6 Pa, nu = 0.45), its x = min face
// moved 20 mm in z over 0.1 s by keyframes: the harness's "shake".
Scene shaken_beam(Integrator integrator, double dt) {
    Scene s;
    s.mesh = make_box(48, 3, 3, 0.005);
    s.materials = Material{1e6, 0.45, 1000};
    s.integrator = integrator;
    s.dt = dt;
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
        if (s.mesh.X[3 * v] < -0.12 + 1e-9)
            s.prescribed.push_back({v, {s.mesh.X[3 * v], s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2] + 0.02}});
    s.prescribed_keyframes = {{0, 0}, {0.05, 0.5}, {0.1, 1}};
    return s;
}

}  // namespace

// Steps that move prescribed vertices are checked too: the gain is the free
// vertices' energy change less the constraints' work (f_c averaged over the
// step times du_c). Converged steps of every integrator balance it within a
// few per cent of the body's energy (energy_growth measured 1.0003-1.0214,
// generalized-alpha-linear the most), where leaving the work out fails the
// first driven steps.
TEST(Simulator, EnergyGuardBalancesTheWorkOfMovingConstraints) {
    for (const auto& [integrator, dt] : {std::pair{Integrator::Explicit, 5e-5}, std::pair{Integrator::Verlet, 5e-5},
                                         std::pair{Integrator::SemiImplicit, 2e-3}, std::pair{Integrator::Newmark, 2e-3},
                                         std::pair{Integrator::NewmarkLinear, 2e-3},
                                         std::pair{Integrator::GeneralizedAlphaLinear, 2e-3},
                                         std::pair{Integrator::Bdf2Linear, 2e-3}}) {
        SCOPED_TRACE(to_string(integrator));
        Scene s = shaken_beam(integrator, dt);
        s.solver.max_energy_growth = 1.1;
        Simulator<double> sim(s);
        double most = 0;
        const int steps = int(std::lround(0.12 / dt));
        for (int k = 0; k < steps; ++k) {
            StepStats st;
            ASSERT_NO_THROW(st = sim.step()) << "step " << k;
            most = std::max(most, st.energy_growth);
        }
        EXPECT_LT(most, 1.1);
    }
}

// A fixed budget of 2 AMG-preconditioned CG iterations per step blows up
// while the beam is driven (to 1e17 m, every step passing, before the
// guard checked driven steps and failed a fixed budget's runaway).
TEST(Simulator, EnergyGuardFailsAFixedBudgetThatBlowsUpWhileDriven) {
    Scene s = shaken_beam(Integrator::GeneralizedAlphaLinear, 2e-3);
    s.solver.preconditioner = PreconditionerKind::Amg;
    s.solver.cg_fixed_iterations = 2;
    Simulator<double> sim(s);
    try {
        for (int k = 0; k < 60; ++k) sim.step();
        FAIL() << "no step failed";
    } catch (const SimulationError& e) {
        EXPECT_NE(std::string(e.what()).find("energy grew without a source"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cg_fixed_iterations: 1000"), std::string::npos) << e.what();
    }
    double umax = 0;
    for (const double x : sim.displacement()) umax = std::max(umax, std::abs(x));
    EXPECT_LT(umax, 1.0);  // the failed step left the state as it was before it
}

namespace {

// Core's operator with deterministic noise of relative size `jitter` (of
// the forces' rms) added to every force evaluation: a residual floor, as
// round-off makes one on stiff or badly shaped meshes.
class JitterOperator final : public test::ForwardingOperator {
public:
    JitterOperator(std::unique_ptr<ElasticOperator<double>> op, double jitter)
        : ForwardingOperator(std::move(op)), jitter_(jitter) {}
    double forces(const double* u, double* f, bool energy) override {
        const double W = op_->forces(u, f, energy);
        const std::size_t n = 3 * std::size_t(num_vertices());
        double rms = 0;
        for (std::size_t i = 0; i < n; ++i) rms += f[i] * f[i];
        rms = std::sqrt(rms / double(n));
        ++calls_;
        for (std::size_t i = 0; i < n; ++i) {
            const double h = std::sin(12.9898 * double(i) + 78.233 * double(calls_)) * 43758.5453;
            f[i] += jitter_ * rms * 2 * (h - std::floor(h) - 0.5);
        }
        return W;
    }

private:
    double jitter_;
    long calls_ = 0;
};

OperatorFactory<double> jitter_factory(double jitter) {
    return [jitter](const Mesh& m, const Materials& mat, ModelKind k, Method me) -> std::unique_ptr<ElasticOperator<double>> {
        return std::make_unique<JitterOperator>(make_cpu_operator<double>(m, mat, k, me), jitter);
    };
}

}  // namespace

// Newton stagnating at a round-off floor above newton_tolerance is
// converged (and says so); one stuck far above round-off still fails with
// its residual in the message.
TEST(Simulator, NewtonAcceptsItsRoundOffFloorButNotAStuckSolve) {
    Scene s = cantilever(Integrator::Implicit, 2e-3);
    s.solver.newton_tolerance = 1e-14;  // below the floor the jitter makes
    Simulator<double> clean(s);
    Simulator<double> floor(s, nullptr, jitter_factory(1e-12));
    for (int k = 0; k < 5; ++k) {
        clean.step();
        const StepStats& st = floor.step();
        EXPECT_TRUE(st.newton_round_off) << k;
        EXPECT_LE(st.residual, std::sqrt(std::numeric_limits<double>::epsilon()));
        EXPECT_GT(st.residual, s.solver.newton_tolerance);
    }
    double diff = 0, ref = 0;
    for (std::size_t i = 0; i < clean.displacement().size(); ++i) {
        diff = std::max(diff, std::abs(clean.displacement()[i] - floor.displacement()[i]));
        ref = std::max(ref, std::abs(clean.displacement()[i]));
    }
    EXPECT_LT(diff, 1e-8 * ref);

    // The static solve shares the criterion.
    Scene st = cantilever(Integrator::Implicit, 2e-3);
    st.solver.newton_tolerance = 1e-14;
    Simulator<double> stat(st, nullptr, jitter_factory(1e-12));
    const StaticResult res = stat.solve_static();
    EXPECT_TRUE(res.converged);
    EXPECT_TRUE(stat.last_stats().newton_round_off);

    // A residual stuck at ~1e-4: a failure, whichever way Newton gives up.
    s.solver.newton_tolerance = 1e-10;
    Simulator<double> stuck(s, nullptr, jitter_factory(1e-3));
    try {
        stuck.step();
        FAIL() << "no error; residual " << stuck.last_stats().residual;
    } catch (const SimulationError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("step 1: "), std::string::npos) << msg;
        EXPECT_NE(msg.find("relative residual"), std::string::npos) << msg;
        EXPECT_FALSE(stuck.last_stats().newton_round_off);
    }
    // Clean solves converge to the tolerance, not the floor.
    Scene ok = cantilever(Integrator::Implicit, 2e-3);
    Simulator<double> plain(ok);
    const StepStats& ps = plain.step();
    EXPECT_FALSE(ps.newton_round_off);
    EXPECT_LE(ps.residual, ok.solver.newton_tolerance);
}

// A Scene filled in by hand reaches the Simulator without a reader's
// validation: every mesh fault is a MeshError naming it, never a crash in
// the topology build or silent nonsense (an inverted or duplicate tet).
TEST(Simulator, HandMadeSceneMeshIsChecked) {
    const auto expect_mesh_error = expect_rejected<MeshError>;
    const Scene good = cantilever(Integrator::SemiImplicit, 1e-3);
    Scene s = good;
    s.mesh.tets[5] = -5;
    expect_mesh_error(s, "out of range");
    s = good;
    s.mesh.tets[6] = s.mesh.num_vertices();
    expect_mesh_error(s, "out of range");
    s = good;
    s.mesh.tets[1] = s.mesh.tets[0];
    expect_mesh_error(s, "twice");
    s = good;
    s.mesh.X[4] = std::numeric_limits<double>::quiet_NaN();
    expect_mesh_error(s, "non-finite");
    s = good;
    s.mesh.region.assign(1, 0);
    expect_mesh_error(s, "region ids");
    s = good;
    s.mesh.X.push_back(0.0);
    expect_mesh_error(s, "multiple of 3");
    s = good;
    std::swap(s.mesh.tets[2], s.mesh.tets[3]);
    expect_mesh_error(s, "inverted");
    s = good;
    s.mesh.tets.insert(s.mesh.tets.end(), s.mesh.tets.begin(), s.mesh.tets.begin() + 4);
    expect_mesh_error(s, "duplicates");
    s = good;
    for (int r = 0; r < 3; ++r) s.mesh.X[3 * s.mesh.tets[3] + r] = s.mesh.X[3 * s.mesh.tets[2] + r];  // flat tet 0
    expect_mesh_error(s, "degenerate");
}

// Enums that arrive as integers (bindings, casts) must name a value.
TEST(Simulator, OutOfRangeEnumsAreErrors) {
    const auto expect_field = expect_rejected<InvalidArgument>;
    Scene s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.integrator = static_cast<Integrator>(42);
    expect_field(s, "\"integrator\"");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.model = static_cast<ModelKind>(-1);
    expect_field(s, "\"model\"");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.method = static_cast<Method>(2);
    expect_field(s, "\"method\"");
    s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.solver.linear_solver = static_cast<LinearSolver>(9);
    expect_field(s, "\"solver.linear_solver\"");
}

// A step that fails leaves the state as it found it (u, v, time, step
// index, bit for bit), so the application can remove the cause and go on;
// before, the exploded state stayed and the next step started from it.
TEST(Simulator, FailedStepLeavesTheStateUntouched) {
    for (const Integrator integrator : {Integrator::Explicit, Integrator::SemiImplicit, Integrator::Implicit}) {
        Scene s = cantilever(integrator, 1e-3);
        if (integrator == Integrator::Implicit) s.solver.newton_max_iterations = 3;
        Simulator<double> sim(std::move(s));
        for (int k = 0; k < 3; ++k) sim.step();
        const std::vector<double> u0(sim.displacement().begin(), sim.displacement().end());
        const std::vector<double> v0(sim.velocity().begin(), sim.velocity().end());
        const double t0 = sim.time();
        const long k0 = sim.step_index();
        const std::size_t tip = sim.displacement().size() - 3;
        sim.external_forces()[tip] = 1e12;  // tears the tip off in one step
        EXPECT_THROW(sim.step(), SimulationError) << to_string(integrator);
        EXPECT_EQ(sim.time(), t0);
        EXPECT_EQ(sim.step_index(), k0);
        EXPECT_TRUE(std::equal(u0.begin(), u0.end(), sim.displacement().begin())) << to_string(integrator);
        EXPECT_TRUE(std::equal(v0.begin(), v0.end(), sim.velocity().begin())) << to_string(integrator);
        const Energies e = sim.energies();
        EXPECT_TRUE(std::isfinite(e.elastic) && std::isfinite(e.kinetic));
        sim.external_forces()[tip] = 0;
        EXPECT_NO_THROW(sim.step()) << to_string(integrator);
        EXPECT_EQ(sim.step_index(), k0 + 1);
    }
}

// Energies too large for floating point are said to be, not printed as NaN.
TEST(Simulator, NonFiniteEnergyIsNamed) {
    Scene s = cantilever(Integrator::SemiImplicit, 1e-3);
    s.gravity = {0, 0, -1e300};
    const auto [msg, vertex] = step_failure(std::move(s), 5);
    EXPECT_EQ(msg.find("nan"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no longer finite"), std::string::npos) << msg;
    EXPECT_GE(vertex, 0) << msg;
}

TEST(Simulator, MovedFromSimulatorThrows) {
    Simulator<double> a(cantilever(Integrator::SemiImplicit, 1e-3));
    Simulator<double> b(std::move(a));
    EXPECT_THROW(a.step(), Error);
    EXPECT_THROW(a.displacement(), Error);
    EXPECT_THROW(a.energies(), Error);
    EXPECT_NO_THROW(b.step());
    a = std::move(b);
    EXPECT_NO_THROW(a.step());
}

// Driven only by a prescribed ramp (no gravity, at rest), the free dofs'
// right-hand side P b is zero: CG's tolerance is relative to what they
// actually see, P(b - A x_c). Dividing by 1 instead, soft bodies stopped
// after 0 iterations with the free vertices unmoved (42 % off the direct
// solve at Y = 1e3).
TEST(Simulator, PrescribedOnlyMotionSolvesToTheRelativeTolerance) {
    for (const double young : {1e5, 1e3, 10.0}) {
        std::vector<double> u_ref;
        for (const LinearSolver ls : {LinearSolver::Direct, LinearSolver::CG}) {
            Scene s = test::clamped_box_scene(4, 1, 1, young);
            s.gravity = {0, 0, 0};
            s.prescribed_steps = 10;
            s.solver.linear_solver = ls;
            double xmax = -1;
            for (index_t v = 0; v < s.mesh.num_vertices(); ++v) xmax = std::max(xmax, s.mesh.X[3 * v]);
            for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
                if (s.mesh.X[3 * v] > xmax - 1e-9)
                    s.prescribed.push_back({v, {s.mesh.X[3 * v] + 1e-4, s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2]}});
            Simulator<double> sim(std::move(s));
            int iterations = 0;
            for (int k = 0; k < 3; ++k) iterations += sim.step().solver_iterations;
            const std::vector<double> u(sim.displacement().begin(), sim.displacement().end());
            if (ls == LinearSolver::Direct) {
                u_ref = u;
                continue;
            }
            EXPECT_GT(iterations, 3) << young;
            EXPECT_LE(test::rel_diff(u, u_ref), 1e-5) << young;  // CG to 1e-6 against the direct solve
        }
    }
}

// The energy guard's bound is relative to the energy the body has had net
// of the gains it has counted: a bent beam released explicitly just past
// the stable step grows 1.2-3x per step, and with the gains in the
// reference it reached 460x its release energy with every step passing.
TEST(Simulator, EnergyGuardCatchesSteadyGrowth) {
    Scene s = test::clamped_box_scene(6, 2, 2, 1e5);
    s.gravity = {0, 0, 0};
    s.integrator = Integrator::Explicit;
    s.dt = 6e-4;  // 3e-4 and 4e-4 are stable
    Simulator<double> sim(s);
    for (index_t v = 0; v < sim.num_vertices(); ++v) {
        const double x = (s.mesh.X[3 * v] - s.mesh.X[0]) / 0.06;
        if (std::find(s.fixed.begin(), s.fixed.end(), v) == s.fixed.end()) sim.displacement()[3 * v + 2] = 0.002 * x * x;
    }
    const Energies e0 = sim.energies();
    const double release = e0.kinetic + e0.elastic;
    double most = release;
    bool caught = false;
    for (int k = 0; k < 40 && !caught; ++k) {
        try {
            sim.step();
            const Energies e = sim.energies();
            most = std::max(most, e.kinetic + e.elastic);
        } catch (const SimulationError&) {
            caught = true;
        }
    }
    EXPECT_TRUE(caught);
    EXPECT_LE(most, s.solver.max_energy_growth * release);
}

// After a static solve the prescribed targets are reached: a step holds
// them there (it restarted the ramp from time 0 and pulled them back).
TEST(Simulator, StepAfterStaticKeepsPrescribedTargets) {
    for (const Integrator integrator : {Integrator::SemiImplicit, Integrator::Implicit, Integrator::Explicit}) {
        Scene s = test::clamped_box_scene(4, 1, 1, 1e5);
        s.integrator = integrator;
        s.dt = integrator == Integrator::Explicit ? 1e-5 : 1e-3;
        s.prescribed_steps = 100;
        const index_t tip = s.mesh.num_vertices() - 1;
        s.prescribed.push_back({tip, {s.mesh.X[3 * tip] + 2e-3, s.mesh.X[3 * tip + 1], s.mesh.X[3 * tip + 2]}});
        Simulator<double> sim(std::move(s));
        sim.solve_static();
        EXPECT_NEAR(sim.displacement()[3 * tip], 2e-3, 1e-12);
        sim.step();
        EXPECT_NEAR(sim.displacement()[3 * tip], 2e-3, 1e-12) << to_string(integrator);
        EXPECT_NEAR(sim.velocity()[3 * tip], 0.0, 1e-9) << to_string(integrator);
    }
}

// An explicit step far past the stability limit from rest: the guard fails
// it and gives either the gain itself or a ratio to the energy the step's
// end holds net of the gain (the work gravity did: since 2026-11-27 part of
// the guard's reference), never a ratio to a reference of 0 J (it printed
// "+6.18e+288 x").
TEST(Simulator, GuardMessageFromRestGivesTheGain) {
    Scene s = test::clamped_box_scene(4, 1, 1, 1e12);
    s.integrator = Integrator::Explicit;
    s.dt = 1e-5;
    const std::string msg = step_failure(std::move(s), 5).first;
    EXPECT_NE(msg.find("energy grew without a source"), std::string::npos) << msg;
    EXPECT_NE(msg.find("a gain of"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("e+2"), std::string::npos) << msg;  // no 1e200-size ratio
}

// Every vertex driven to its mirror image (x -> -x): every tet ends the
// step inverted. The step is counted (StepStats::inverted_tets) and, with
// solver.fail_on_inverted, fails with a SimulationError naming the count.
TEST(Simulator, FailOnInvertedTets) {
    for (const Integrator integrator : {Integrator::Explicit, Integrator::Implicit}) {
        Scene s;
        s.mesh = make_box(2, 1, 1);
        s.integrator = integrator;
        s.dt = 1e-3;
        for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
            s.prescribed.push_back({v, {-s.mesh.X[3 * v], s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2]}});
        {
            Simulator<double> sim(s);
            EXPECT_EQ(sim.step().inverted_tets, s.mesh.num_tets()) << to_string(integrator);
        }
        s.solver.fail_on_inverted = true;
        Simulator<double> sim(s);
        try {
            sim.step();
            ADD_FAILURE() << "no error with fail_on_inverted (" << to_string(integrator) << ")";
        } catch (const SimulationError& e) {
            EXPECT_EQ(e.step(), 1);
            EXPECT_NE(std::string(e.what()).find("12 inverted tets"), std::string::npos) << e.what();
        }
        s.count_inverted_tets = false;
        EXPECT_THROW(s.validate(), InvalidArgument);
    }
}
