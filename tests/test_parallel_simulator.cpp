// A whole semi-implicit Simulator step on the parallel back-ends (the
// executor runs the CG vector operations, the operator factory the
// kernels): colour and gather bitwise the same for any thread count and
// equal to their SerialExecutor run; atomic and private close to it; every
// variant close to the core's serial Simulator.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "edgefem/core/inverted_tets.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "cpu/cpu_operator.hpp"
#include "cantilever.hpp"
#include "models.hpp"
#include "test_threads.hpp"

using namespace edgefem;
using edgefem::test::rel_diff;

namespace {

Scene cantilever(Method method) {
    Scene s = edgefem::test::clamped_box_scene(8, 3, 3);
    s.integrator = Integrator::SemiImplicit;
    s.method = method;
    s.dt = 2e-3;
    s.solver.cg_tolerance = 1e-10;
    s.solver.cg_max_iterations = 2000;
    s.count_inverted_tets = true;
    return s;
}

struct Result {
    std::vector<double> u, v;
    int iterations = 0;
    double elastic = 0;
};

Result run(Method method, std::shared_ptr<const Executor> ex, OperatorFactory<double> factory) {
    Simulator<double> sim(cantilever(method), ex, std::move(factory));
    Result r;
    for (int k = 0; k < 4; ++k) r.iterations += sim.step().solver_iterations;
    r.u.assign(sim.displacement().begin(), sim.displacement().end());
    r.v.assign(sim.velocity().begin(), sim.velocity().end());
    r.elastic = sim.energies().elastic;
    return r;
}

using test::bitwise_equal;

}  // namespace

TEST(ParallelSimulator, SemiImplicitStepDeterministic) {
    for (Method method : {Method::Edge, Method::Tet}) {
        const Result core = run(method, nullptr, {});
        EXPECT_GT(edgefem::test::max_abs(core.u), 0);
        for (Variant var : kAllVariants) {
            const auto serial_ex = std::make_shared<SerialExecutor>();
            const Result serial = run(method, serial_ex, cpu_operator_factory<double>({serial_ex, var}));
            const std::string tag = std::string(method == Method::Edge ? "edge/" : "tet/") + to_string(var);
            EXPECT_LE(rel_diff(serial.u, core.u), 1e-12) << tag;
            EXPECT_LE(rel_diff(serial.v, core.v), 1e-12) << tag;
            for (ExecutorKind b : test::threaded_executor_kinds())
                for (int t : edgefem::test::test_thread_counts()) {
                    const auto ex = make_executor(b, t);
                    const Result par = run(method, ex, cpu_operator_factory<double>({ex, var}));
                    const std::string where = tag + "/" + to_string(b) + "-" + std::to_string(t);
                    if (is_deterministic(var) || (method == Method::Tet && var != Variant::Private)) {
                        EXPECT_TRUE(bitwise_equal(par.u, serial.u)) << where << " " << rel_diff(par.u, serial.u);
                        EXPECT_TRUE(bitwise_equal(par.v, serial.v)) << where;
                        EXPECT_EQ(par.iterations, serial.iterations) << where;
                        EXPECT_EQ(par.elastic, serial.elastic) << where;
                    } else {
                        EXPECT_LE(rel_diff(par.u, serial.u), 1e-12) << where;
                        EXPECT_LE(rel_diff(par.v, serial.v), 1e-12) << where;
                    }
                }
        }
    }
}

TEST(ParallelSimulator, InvertedTetCount) {
    Scene s = cantilever(Method::Edge);
    const auto ex = make_executor(test::kThreadSanitizer ? ExecutorKind::Pool : ExecutorKind::TBB, 3);
    std::vector<double> u(s.mesh.X.size(), 0.0);
    // Collapse a few vertices onto the origin: inverts or flattens some tets.
    for (int v = 0; v < 20; ++v)
        for (int r = 0; r < 3; ++r) u[3 * v + r] = -s.mesh.X[3 * v + r] + (r == 0 ? 0.05 : 0);
    std::size_t serial = 0;
    for (index_t t = 0; t < s.mesh.num_tets(); ++t) {
        double x[4][3];
        for (int k = 0; k < 4; ++k)
            for (int r = 0; r < 3; ++r) {
                const index_t v = s.mesh.tets[4 * t + k];
                x[k][r] = s.mesh.X[3 * v + r] + u[3 * v + r];
            }
        serial += signed_volume(x[0], x[1], x[2], x[3]) <= 0;
    }
    EXPECT_GT(serial, 0u);
    EXPECT_EQ(count_inverted_tets_parallel(*ex, s.mesh, u.data()), index_t(serial));
    // Core's count (deformed positions first) and the parallel one with a
    // reused scratch, at other thread counts and in float.
    EXPECT_EQ(count_inverted_tets(s.mesh, u.data()), index_t(serial));
    std::vector<double> scratch;
    const std::vector<float> uf(u.begin(), u.end());
    for (int threads : {1, 2, 4}) {
        const auto omp = make_executor(ExecutorKind::OpenMP, threads);
        EXPECT_EQ(count_inverted_tets_parallel(*omp, s.mesh, u.data(), scratch), index_t(serial));
        EXPECT_EQ(count_inverted_tets_parallel(*omp, s.mesh, uf.data(), scratch), count_inverted_tets(s.mesh, uf.data()));
    }
}

// The implicit integrator and a static solve (Newton: its residual, norms,
// slopes, line search and state updates run on the executor's blocks, with
// damping so that every term of the residual is in play): bitwise the same
// for every back-end and thread count as on the SerialExecutor, for the
// deterministic variants, and close to core's serial Simulator.
TEST(ParallelSimulator, ImplicitAndStaticDeterministic) {
    Scene dyn = cantilever(Method::Edge);
    dyn.integrator = Integrator::Implicit;
    dyn.rayleigh_alpha = 0.5;
    dyn.rayleigh_beta = 1e-3;
    const auto run_both = [&](std::shared_ptr<const Executor> ex, OperatorFactory<double> factory) {
        Simulator<double> sim(dyn, ex, factory);
        sim.step();
        sim.step();
        std::vector<double> out(sim.displacement().begin(), sim.displacement().end());
        out.insert(out.end(), sim.velocity().begin(), sim.velocity().end());
        Simulator<double> st(edgefem::test::clamped_box_scene(8, 3, 3), ex, factory);
        const StaticResult res = st.solve_static();
        EXPECT_TRUE(res.converged);
        out.insert(out.end(), st.displacement().begin(), st.displacement().end());
        return out;
    };
    const std::vector<double> core = run_both(nullptr, {});
    EXPECT_GT(edgefem::test::max_abs(core), 0);
    for (Variant var : {Variant::Auto, Variant::Gather, Variant::Colour}) {
        const auto serial_ex = std::make_shared<SerialExecutor>();
        const std::vector<double> serial = run_both(serial_ex, cpu_operator_factory<double>({serial_ex, var}));
        EXPECT_LE(rel_diff(serial, core), 1e-9) << to_string(var);
        for (ExecutorKind b : test::threaded_executor_kinds())
            for (int t : edgefem::test::test_thread_counts()) {
                const auto ex = make_executor(b, t);
                EXPECT_TRUE(bitwise_equal(run_both(ex, cpu_operator_factory<double>({ex, var})), serial))
                    << to_string(var) << "/" << to_string(b) << "-" << t;
            }
    }
}
