// The back-ends (backend.hpp): the reference back-end's vector kernels
// (plain serial loops) against the CPU back-end's (fixed blocks on an
// executor) kernel by kernel, Simulator runs on both, the CPU back-end
// bitwise the same for any thread count, and a back-end whose memory is
// not host memory: no step reads its vectors on the host.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "edgefem/core/backend.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "cantilever.hpp"
#include "models.hpp"
#include "test_threads.hpp"

using namespace edgefem;
using edgefem::test::rel_diff;

namespace {

using test::bitwise_equal;

// Host memory that says it is device memory: host() refuses it, while the
// CPU kernels still run on it.
class PretendDeviceMemory final : public VectorMemory {
public:
    MemorySpace space() const override { return MemorySpace::Device; }
    std::shared_ptr<void> allocate(std::size_t bytes) const override { return host_memory().allocate(bytes); }
    void to_host(void* host, const void* data, std::size_t bytes) const override {
        host_memory().to_host(host, data, bytes);
    }
    void from_host(void* data, const void* host, std::size_t bytes) const override {
        host_memory().from_host(data, host, bytes);
    }
};

// The CPU back-end on PretendDeviceMemory.
class PretendDeviceBackend final : public Backend<double> {
public:
    const char* name() const override { return "pretend-device"; }
    int threads() const override { return 1; }
    std::unique_ptr<ElasticOperator<double>> make_operator(const Mesh& m, const Materials& mat, ModelKind k,
                                                           Method me) const override {
        return cpu_->make_operator(m, mat, k, me);
    }
    const VectorKernels<double>& kernels() const override { return cpu_->kernels(); }
    const VectorMemory& memory() const override { return memory_; }

private:
    std::shared_ptr<const Backend<double>> cpu_ = make_cpu_backend<double>();
    PretendDeviceMemory memory_;
};

// ---- kernels ----

constexpr std::size_t kDofs = 3 * 1100;  // 9 blocks of kVectorBlock: several groups on 2 threads

struct Inputs {
    std::vector<double> a, b, c, mass, mass_dof, D, D0;
    std::vector<std::uint8_t> free_dof;
    std::vector<index_t> con_vertex;
    std::vector<double> con_disp;
};

Inputs make_inputs() {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(-1, 1);
    Inputs in;
    const std::size_t nv = kDofs / 3;
    for (auto* v : {&in.a, &in.b, &in.c}) {
        v->resize(kDofs);
        for (double& x : *v) x = U(rng);
    }
    in.mass.resize(nv);
    for (double& m : in.mass) m = 1 + 0.5 * U(rng);
    for (std::size_t i = 0; i < kDofs; ++i) in.mass_dof.push_back(in.mass[i / 3]);
    // Diagonal blocks: symmetric, most positive definite, every tenth not.
    in.D.resize(9 * nv);
    for (std::size_t v = 0; v < nv; ++v) {
        double* B = &in.D[9 * v];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j <= i; ++j) B[3 * i + j] = B[3 * j + i] = (i == j ? 4.0 : 0.0) + 0.5 * U(rng);
        if (v % 10 == 0) B[4] = -3;
    }
    in.D0 = in.D;
    for (double& x : in.D0) x *= 0.5;
    in.free_dof.assign(kDofs, 1);
    for (std::size_t v = 0; v < nv; v += 37) {
        in.con_vertex.push_back(index_t(v));
        for (int r = 0; r < 3; ++r) {
            in.free_dof[3 * v + r] = 0;
            in.con_disp.push_back(0.01 * U(rng));
        }
    }
    return in;
}

// Every kernel but cg on the same inputs; the outputs in one vector.
std::vector<double> run_kernels(const VectorKernels<double>& k, const Inputs& in) {
    const std::size_t n = kDofs;
    std::vector<double> out, x = in.a, y = in.b, z = in.c, w(n), R(n), inertia(n);
    const auto put = [&](const std::vector<double>& v) { out.insert(out.end(), v.begin(), v.end()); };
    const std::array<double, 3> g{0.5, -9.81, 1.5};
    const ConstraintView con{in.con_vertex.data(), in.con_disp.data(), in.con_vertex.size()};

    k.external_load(w.data(), in.a.data(), in.mass.data(), g, 0.75, n);
    put(w);
    k.explicit_velocity(w.data(), in.a.data(), in.b.data(), in.c.data(), in.mass.data(), 1e-3, 1.01, n);
    put(w);
    k.semi_implicit_rhs(w.data(), x.data(), in.a.data(), in.b.data(), in.c.data(), in.mass.data(), 1e-3, n);
    put(w);
    put(x);
    x = in.a;
    y = in.b;
    k.take_velocity(x.data(), y.data(), in.c.data(), 2e-3, n);
    put(x);
    put(y);
    k.implicit_predict(x.data(), y.data(), in.a.data(), in.b.data(), 2e-3, n);
    put(x);
    put(y);
    k.implicit_velocity(w.data(), in.a.data(), in.b.data(), 2e-3, n);
    put(w);
    k.newton_increment(w.data(), in.a.data(), in.b.data(), n);
    put(w);
    k.newton_increment(w.data(), in.a.data(), nullptr, n);
    put(w);
    k.newton_rhs(w.data(), x.data(), in.c.data(), n);
    put(w);
    put(x);
    k.scaled_gradient(w.data(), in.c.data(), in.mass.data(), 3.0, n);
    put(w);
    k.line_search_point(w.data(), in.a.data(), in.b.data(), 0.25, n);
    put(w);
    x = in.a;
    y = in.b;
    k.rescale(x.data(), y.data(), n, 0x1p-60, true);
    put(x);
    put(y);
    k.to_state(w.data(), in.c.data(), n);
    k.from_state(x.data(), w.data(), n);
    put(x);
    k.copy(w.data(), in.b.data(), n);
    put(w);
    k.fill(w.data(), n, 2.5);
    put(w);

    w = in.a;
    k.constrained_velocities(w.data(), in.b.data(), con, 0.5, 1e-3);
    put(w);
    w = in.a;
    k.hold_constraints(w.data(), con, 0.5);
    put(w);
    out.push_back(k.constraints_move(w.data(), con, 0.5, 1e-15));
    out.push_back(k.constraints_move(w.data(), con, 0.6, 1e-15));

    w = in.a;
    out.push_back(k.count_differences(w.data(), in.a.data(), n));
    w[5] = 7;
    w[n - 1] = 7;
    out.push_back(k.count_differences(w.data(), in.a.data(), n));
    for (double e : k.energy_sums(in.a.data(), in.b.data(), in.c.data(), in.mass.data(), g, n)) out.push_back(e);
    out.push_back(double(k.first_non_finite(in.a.data(), in.b.data(), n)));
    w = in.b;
    w[2000] = NAN;
    w[1000] = INFINITY;
    out.push_back(double(k.first_non_finite(in.a.data(), w.data(), n)));
    x = in.a;
    for (double& v : x) v *= 1e-200;  // squares underflow without the scaling
    const Scaled sd = k.scaled_dot(x.data(), in.b.data(), n);
    out.push_back(sd.mant);
    out.push_back(sd.exp);
    out.push_back(k.scaled_norm(x.data(), n) * 1e200);
    out.push_back(k.scaled_norm_state(in.c.data(), n));
    for (bool dynamic : {true, false}) {
        const NewtonResidualArgs<double> args{R.data(),       inertia.data(), in.a.data(),  in.b.data(),
                                              in.c.data(),    in.mass.data(), in.b.data(),  in.c.data(),
                                              in.a.data(),    in.free_dof.data(), dynamic,   2.5e5,
                                              500.0,          0.5,            0.25};
        for (double s : k.newton_residual(args, n)) out.push_back(s);
        put(R);
        put(inertia);
    }
    for (double m : k.solve_magnitudes(in.a.data(), in.b.data(), in.mass_dof.data(), in.free_dof.data(), n))
        out.push_back(m);

    for (double c_b : {0.0, 0.3}) {
        w = in.b;
        k.system_diagonal(n, 2.0, 0.5, c_b, in.mass_dof.data(), in.a.data(), in.c.data(), w.data());
        put(w);
        w = in.b;
        k.system_diagonal_range(0, 384, 2.0, 0.5, c_b, in.mass_dof.data(), in.a.data(), in.c.data(), w.data());
        k.system_diagonal_range(384, n, 2.0, 0.5, c_b, in.mass_dof.data(), in.a.data(), in.c.data(), w.data());
        put(w);
        std::vector<double> Dinv(3 * n + 1);
        k.block_jacobi_build(Dinv.data(), in.D.data(), c_b != 0 ? in.D0.data() : nullptr, in.mass.data(), 0.1, 1.0,
                             c_b, n);
        put(Dinv);
        k.block_jacobi_apply_range(0, n, Dinv.data(), in.a.data(), w.data());
        put(w);
    }
    return out;
}

// A: a 1-D chain of springs per coordinate plus c_m M (SPD), for the cg
// kernel; its diagonal blocks for block-Jacobi.
class ChainSystem final : public CgSystem {
public:
    ChainSystem(const VectorKernels<double>& k, const Inputs& in) : k_(k), in_(in) {}
    void products(const double* x, double* y) override {
        const std::size_t n = kDofs;
        for (std::size_t i = 0; i < n; ++i)
            y[i] = 2 * x[i] - (i >= 3 ? x[i - 3] : 0.0) - (i + 3 < n ? x[i + 3] : 0.0);
    }
    void finish(std::size_t lo, std::size_t hi, const double* x, double* y) const override {
        k_.system_diagonal_range(lo, hi, 0.05, 1.0, 0.0, in_.mass_dof.data(), x, nullptr, y);
    }

private:
    const VectorKernels<double>& k_;
    const Inputs& in_;
};

class KernelJacobi final : public CgPreconditioner {
public:
    KernelJacobi(const VectorKernels<double>& k, const Inputs& in) : k_(k), Dinv_(3 * kDofs + 1) {
        std::vector<double> D(3 * kDofs, 0.0);
        for (std::size_t v = 0; v < kDofs / 3; ++v)
            for (int r = 0; r < 3; ++r) D[9 * v + 4 * r] = 2;
        k.block_jacobi_build(Dinv_.data(), D.data(), nullptr, in.mass.data(), 0.05, 1.0, 0.0, kDofs);
    }
    void apply(std::size_t lo, std::size_t hi, const double* r, double* z) const override {
        k_.block_jacobi_apply_range(lo, hi, Dinv_.data(), r, z);
    }

private:
    const VectorKernels<double>& k_;
    std::vector<double> Dinv_;
};

struct CgRun {
    std::vector<double> x;
    CgResult res;
};

CgRun run_cg(const VectorKernels<double>& k, const Inputs& in, int fixed_iterations) {
    ChainSystem A(k, in);
    KernelJacobi M(k, in);
    CgRun run;
    run.x.assign(kDofs, 0.0);
    for (std::size_t i = 0; i < kDofs; ++i)
        if (!in.free_dof[i]) run.x[i] = in.a[i];  // moving constraints
    CgWork work;
    run.res = k.cg(A, M, in.free_dof.data(), in.b.data(), run.x.data(), kDofs, {1e-11, 2000, fixed_iterations}, work);
    return run;
}

// |P(b - A x)| / |P b|.
double chain_residual(const Inputs& in, const std::vector<double>& x) {
    const auto backend = make_reference_backend<double>();  // alive while its kernels are used
    ChainSystem A(backend->kernels(), in);
    std::vector<double> Ax(kDofs);
    A.products(x.data(), Ax.data());
    A.finish(0, kDofs, x.data(), Ax.data());
    double rr = 0, bb = 0;
    for (std::size_t i = 0; i < kDofs; ++i)
        if (in.free_dof[i]) {
            rr += (in.b[i] - Ax[i]) * (in.b[i] - Ax[i]);
            bb += in.b[i] * in.b[i];
        }
    return std::sqrt(rr / bb);
}

// ---- simulations ----

struct SimRun {
    std::vector<double> state;  // u, v after each step (or the static solve)
    int iterations = 0;
};

Scene semi_implicit_scene() {
    Scene s = test::clamped_box_scene(8, 3, 3);
    s.rayleigh_alpha = 0.5;
    s.dt = 2e-3;
    s.solver.cg_tolerance = 1e-11;
    s.solver.cg_max_iterations = 3000;
    return s;
}

Scene implicit_scene() {
    Scene s = semi_implicit_scene();
    s.integrator = Integrator::Implicit;
    s.rayleigh_beta = 1e-3;
    s.dt = 5e-3;
    const index_t v = s.mesh.num_vertices() - 1;
    s.prescribed.push_back({v, {s.mesh.X[3 * v] + 0.005, s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2]}});
    s.prescribed_steps = 2;
    return s;
}

Scene explicit_scene() {
    Scene s = semi_implicit_scene();
    s.integrator = Integrator::Explicit;
    s.dt = 1e-4;
    return s;
}

// With stiffness damping: a K built and applied in every explicit step.
Scene explicit_damped_scene() {
    Scene s = explicit_scene();
    s.rayleigh_beta = 2e-4;
    return s;
}

SimRun simulate(const Scene& scene, std::shared_ptr<const Backend<double>> backend, int steps,
             bool static_first = false) {
    Simulator<double> sim(scene, std::move(backend));
    SimRun r;
    const auto record = [&] {
        r.state.insert(r.state.end(), sim.displacement().begin(), sim.displacement().end());
        r.state.insert(r.state.end(), sim.velocity().begin(), sim.velocity().end());
    };
    if (static_first) {
        const StaticResult res = sim.solve_static();
        EXPECT_TRUE(res.converged);
        r.iterations += res.newton_iterations;
        record();
    }
    for (int k = 0; k < steps; ++k) {
        r.iterations += sim.step().solver_iterations;
        record();
    }
    return r;
}

}  // namespace

TEST(BackendVector, HostAccessCopiesAndSizes) {
    BackendVector<double> v(host_memory(), 5);
    ASSERT_EQ(v.size(), 5u);
    for (double x : v.host()) EXPECT_EQ(x, 0.0);
    const std::vector<double> in{1, 2, 3, 4, 5};
    v.write(in);
    std::vector<double> out(5);
    v.read(out);
    EXPECT_EQ(out, in);
    EXPECT_EQ(v.host()[2], 3.0);
    EXPECT_THROW(v.write(std::vector<double>(4)), InvalidArgument);
    v.resize(5);  // same size: kept
    EXPECT_EQ(v.host()[4], 5.0);
    v.resize(7);  // new size: zeros
    for (double x : v.host()) EXPECT_EQ(x, 0.0);
    BackendVector<double> moved = std::move(v);
    EXPECT_EQ(moved.size(), 7u);

    PretendDeviceMemory device;
    BackendVector<float> d(device, 3);
    EXPECT_THROW(d.host(), Error);
    d.write(std::vector<float>{1, 2, 3});
    std::vector<float> scratch;
    const std::span<const float> h = d.read_host(scratch);
    EXPECT_EQ(h.data(), scratch.data());  // a copy
    EXPECT_EQ(h[1], 2.0f);
}

// Every kernel but cg: reference and CPU agree to 1e-12 relative, 1 for
// values below 1 (element-wise: the same formula, up to where the compiler
// fused a product into an FMA; sums: in other orders; 1.2e-14 seen). The
// CPU back-end: bitwise the same on 1, 2 and 3 threads.
TEST(VectorKernels, ReferenceAndCpuAgree) {
    const Inputs in = make_inputs();
    const std::vector<double> ref = run_kernels(make_reference_backend<double>()->kernels(), in);
    const std::vector<double> serial = run_kernels(make_cpu_backend<double>()->kernels(), in);
    ASSERT_EQ(ref.size(), serial.size());
    double worst = 0;
    std::size_t worst_at = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
        const double d = std::abs(ref[i] - serial[i]) / std::max(1.0, std::abs(ref[i]));
        if (d > worst) worst = d, worst_at = i;
    }
    EXPECT_LE(worst, 1e-12) << "at output " << worst_at;
    for (int threads : {2, 3}) {
        const auto ex = make_executor(ExecutorKind::OpenMP, threads);
        EXPECT_TRUE(bitwise_equal(run_kernels(make_cpu_backend<double>(ex)->kernels(), in), serial)) << threads;
    }
}

// The kernels' few special values, checked directly.
TEST(VectorKernels, ReductionsFindWhatTheyLookFor) {
    const Inputs in = make_inputs();
    for (const auto& backend : {make_reference_backend<double>(), make_cpu_backend<double>()}) {
        const VectorKernels<double>& k = backend->kernels();
        std::vector<double> v = in.b;
        EXPECT_EQ(k.first_non_finite(in.a.data(), v.data(), kDofs), kDofs);
        v[2900] = NAN;
        v[1000] = INFINITY;
        EXPECT_EQ(k.first_non_finite(in.a.data(), v.data(), kDofs), 1000u) << backend->name();
        std::vector<double> tiny = in.a;
        for (double& x : tiny) x *= 1e-170;
        double plain = 0;
        for (double x : tiny) plain += x * x;
        EXPECT_EQ(plain, 0.0);  // underflows
        double ref = 0;
        for (double x : in.a) ref += x * x;
        EXPECT_NEAR(k.scaled_norm(tiny.data(), kDofs) * 1e170, std::sqrt(ref), 1e-12 * std::sqrt(ref));
        EXPECT_EQ(k.count_differences(in.a.data(), in.a.data(), kDofs), 0.0);
        const std::array<double, 3> m =
            k.solve_magnitudes(in.a.data(), in.b.data(), in.mass_dof.data(), in.free_dof.data(), kDofs);
        EXPECT_EQ(m[1], test::max_abs(in.b));
    }
}

// CG: the reference's plain passes and the CPU's fused form reach the same
// solution (1e-10 relative: the sums' order changes the iterates by
// round-off; 1e-15 seen) in the same number of iterations give or take
// one; the CPU form is bitwise the same on 1, 2 and 3 threads, also with a
// fixed iteration budget.
TEST(VectorKernels, CgReferenceAndFusedAgree) {
    const Inputs in = make_inputs();
    const CgRun ref = run_cg(make_reference_backend<double>()->kernels(), in, 0);
    const CgRun cpu = run_cg(make_cpu_backend<double>()->kernels(), in, 0);
    EXPECT_TRUE(ref.res.converged);
    EXPECT_TRUE(cpu.res.converged);
    EXPECT_GT(ref.res.iterations, 10);
    EXPECT_LE(std::abs(ref.res.iterations - cpu.res.iterations), 1);
    EXPECT_LE(chain_residual(in, ref.x), 1e-10);
    EXPECT_LE(chain_residual(in, cpu.x), 1e-10);
    EXPECT_LE(rel_diff(cpu.x, ref.x), 1e-10);
    for (std::size_t i = 0; i < kDofs; ++i)
        if (!in.free_dof[i]) {
            ASSERT_EQ(cpu.x[i], in.a[i]);  // constrained values kept
        }
    const CgRun fixed = run_cg(make_cpu_backend<double>()->kernels(), in, 7);
    EXPECT_EQ(fixed.res.iterations, 7);
    for (int threads : {2, 3}) {
        const auto ex = make_executor(ExecutorKind::OpenMP, threads);
        const CgRun par = run_cg(make_cpu_backend<double>(ex)->kernels(), in, 0);
        EXPECT_TRUE(bitwise_equal(par.x, cpu.x)) << threads;
        EXPECT_EQ(par.res.iterations, cpu.res.iterations);
        EXPECT_TRUE(bitwise_equal(run_cg(make_cpu_backend<double>(ex)->kernels(), in, 7).x, fixed.x)) << threads;
    }
}

// Whole simulations on the reference back-end against the CPU back-end on
// 1 and 2 threads (with the reference operator, and with the CPU back-end's
// gather operator): the
// sums run in other orders, so the states differ by round-off, which the
// solves (CG to 1e-11, Newton to 1e-10) keep small: 1e-10 relative (7e-14
// seen).
TEST(Backends, SimulatorOnReferenceAndCpuAgree) {
    struct Case {
        std::string name;
        Scene scene;
        int steps;
        bool static_first;
    };
    std::vector<Case> cases{{"semi-implicit", semi_implicit_scene(), 4, false},
                            {"implicit", implicit_scene(), 3, false},
                            {"explicit", explicit_scene(), 20, false},
                            {"explicit, beta", explicit_damped_scene(), 20, false},
                            {"static", test::clamped_box_scene(8, 3, 3), 1, true}};
    const auto omp2 = make_executor(ExecutorKind::OpenMP, 2);
    for (const Case& c : cases) {
        const SimRun ref = simulate(c.scene, make_reference_backend<double>(), c.steps, c.static_first);
        ASSERT_GT(test::max_abs(ref.state), 0) << c.name;
        const SimRun serial = simulate(c.scene, make_cpu_backend<double>(), c.steps, c.static_first);
        const SimRun two = simulate(c.scene, make_cpu_backend<double>(omp2), c.steps, c.static_first);
        const SimRun gather =
            simulate(c.scene, make_cpu_backend<double>(omp2, cpu_operator_factory<double>({omp2, Variant::Gather})),
                     c.steps, c.static_first);
        EXPECT_LE(rel_diff(serial.state, ref.state), 1e-10) << c.name;
        EXPECT_TRUE(bitwise_equal(two.state, serial.state)) << c.name;
        EXPECT_LE(rel_diff(gather.state, ref.state), 1e-10) << c.name;
    }
}

// The CPU back-end made explicitly is the executor constructor's back-end,
// bitwise, and bitwise the same for every thread count on every executor.
TEST(Backends, CpuBackendBitwiseAcrossThreadCounts) {
    const Scene scene = implicit_scene();
    const auto serial_ex = std::make_shared<SerialExecutor>();
    const auto gather_backend = [](std::shared_ptr<const Executor> ex) {
        return make_cpu_backend<double>(ex, cpu_operator_factory<double>({ex, Variant::Gather}));
    };
    const SimRun base = simulate(scene, gather_backend(serial_ex), 2);
    {
        Simulator<double> adapter(scene, serial_ex, cpu_operator_factory<double>({serial_ex, Variant::Gather}));
        adapter.step();
        adapter.step();
        const std::vector<double> u(adapter.displacement().begin(), adapter.displacement().end());
        const std::vector<double> tail(base.state.end() - 2 * std::ptrdiff_t(u.size()),
                                       base.state.end() - std::ptrdiff_t(u.size()));
        EXPECT_TRUE(bitwise_equal(u, tail));
    }
    for (ExecutorKind b : test::threaded_executor_kinds())
        for (int t : test::test_thread_counts()) {
            const auto ex = make_executor(b, t);
            const SimRun par = simulate(scene, gather_backend(ex), 2);
            EXPECT_TRUE(bitwise_equal(par.state, base.state)) << to_string(b) << "-" << t;
            EXPECT_EQ(par.iterations, base.iterations);
        }
}

// On a back-end whose vectors are not in host memory, steps (semi-implicit,
// implicit, explicit) and the static solve never read a vector on the host:
// they run, with the CPU back-end's results; the views are host copies with
// the same values, a view written between steps takes effect at the next
// step, and the direct solver (host-only) says so.
TEST(Backends, DeviceMemoryIsNeverReadOnTheHostInAStep) {
    const auto device = std::make_shared<PretendDeviceBackend>();
    for (const auto& [scene, steps, static_first] :
         {std::tuple{semi_implicit_scene(), 3, false}, std::tuple{implicit_scene(), 2, false},
          std::tuple{explicit_scene(), 5, false}, std::tuple{explicit_damped_scene(), 5, false},
          std::tuple{test::clamped_box_scene(8, 3, 3), 1, true}}) {
        // block-Jacobi on both: "auto" never takes the host-only AMG off the
        // host, and would take it on the CPU where a solve needs > 100 its
        Scene scene_bj = scene;
        scene_bj.solver.preconditioner = PreconditionerKind::BlockJacobi;
        Simulator<double> sim(scene_bj, device), untouched(scene_bj, device);
        Simulator<double> cpu(scene_bj, make_cpu_backend<double>());
        for (Simulator<double>* s : {&sim, &untouched, &cpu}) {
            if (static_first) s->solve_static();
            for (int k = 0; k < steps; ++k) s->step();
        }
        EXPECT_TRUE(bitwise_equal(sim.positions(), cpu.positions()));
        EXPECT_EQ(sim.energies().kinetic, cpu.energies().kinetic);
        const auto same = [](auto a, auto b) { return std::equal(a.begin(), a.end(), b.begin(), b.end()); };
        EXPECT_TRUE(same(sim.displacement(), cpu.displacement()));
        EXPECT_TRUE(same(sim.velocity(), cpu.velocity()));
        EXPECT_TRUE(same(sim.forces(), cpu.forces()));
        // A push on vertex 5 and a nudged velocity, through the views.
        for (Simulator<double>* s : {&sim, &cpu}) {
            s->external_forces()[15] = 0.5;
            s->velocity()[16] += 1e-3;
        }
        for (Simulator<double>* s : {&sim, &untouched, &cpu}) s->step();
        EXPECT_TRUE(bitwise_equal(sim.positions(), cpu.positions()));
        EXPECT_FALSE(bitwise_equal(sim.positions(), untouched.positions()));
        EXPECT_TRUE(same(sim.forces(), cpu.forces()));
    }
    // The AMG preconditioner runs on the host: refused by name, not a crash.
    Scene amg = semi_implicit_scene();
    amg.solver.preconditioner = PreconditionerKind::Amg;
    try {
        Simulator<double> s(amg, device);
        s.step();
        ADD_FAILURE() << "AMG ran on device memory";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("solver.preconditioner"), std::string::npos) << e.what();
    }
    Scene direct = semi_implicit_scene();
    direct.solver.linear_solver = LinearSolver::Direct;
    Simulator<double> sim(direct, device);
    try {
        sim.step();
        ADD_FAILURE() << "the direct solver ran on device memory";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("host access to device memory"), std::string::npos) << e.what();
    }
}

// Every integrator (Rayleigh alpha and beta, fixed and a prescribed vertex;
// the explicit ones without beta) on the reference back-end against the
// CPU back-end (1e-10 relative, as above), and on memory that is not the
// host's: no step reads a vector on the host, the results bitwise the
// CPU back-end's.
TEST(Backends, EveryIntegratorOnEveryBackend) {
    const auto device = std::make_shared<PretendDeviceBackend>();
    for (const auto& [name, integ] : integrator_names()) {
        SCOPED_TRACE(name);
        Scene scene = is_explicit(integ) ? explicit_scene() : implicit_scene();
        scene.integrator = integ;
        if (is_explicit(integ)) {
            scene.prescribed = implicit_scene().prescribed;
            scene.prescribed_steps = 20;
        }
        const int steps = is_explicit(integ) ? 20 : 4;
        const SimRun ref = simulate(scene, make_reference_backend<double>(), steps);
        const SimRun cpu = simulate(scene, make_cpu_backend<double>(), steps);
        ASSERT_GT(test::max_abs(ref.state), 0);
        EXPECT_LE(rel_diff(cpu.state, ref.state), 1e-10);
        // the pretend device never takes the host-only AMG: block-Jacobi on both
        Scene scene_bj = scene;
        scene_bj.solver.preconditioner = PreconditionerKind::BlockJacobi;
        Simulator<double> sim(scene_bj, device);
        Simulator<double> host(scene_bj, make_cpu_backend<double>());
        for (int k = 0; k < steps; ++k) {
            sim.step();
            host.step();
        }
        EXPECT_TRUE(bitwise_equal(sim.positions(), host.positions()));
    }
}

// The back-ends say what they are.
TEST(Backends, NamesAndThreads) {
    EXPECT_STREQ(make_reference_backend<double>()->name(), "reference");
    EXPECT_STREQ(make_cpu_backend<float>()->name(), "serial");
    const auto ex = make_executor(ExecutorKind::OpenMP, 2);
    EXPECT_EQ(make_cpu_backend<double>(ex)->threads(), 2);
    EXPECT_STREQ(make_cpu_backend<double>(ex)->name(), "omp");
}
