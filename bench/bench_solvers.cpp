// The linear solvers compared on one machine in one run (docs/solvers.md):
//  direct  the built-in beam's system (12,000 dofs): the old factorisation
//          (Eigen SimplicialLDLT, analysis + factorisation every step, as
//          direct_solver.cpp did before CHOLMOD) against CHOLMOD's (the
//          analysis once, then the numeric factorisation), alternating rounds;
//          the whole per-step set-up of each path (K, assembly, factorisation)
//  step    semi-implicit steps with CG to 1e-6, block-Jacobi against AMG,
//          alternating steps of two simulators: ms per step, CG iterations,
//          set-up (K and the preconditioner), the AMG's first (building) step
//  matrix  one assembled system A = M + dt^2 K per mesh and dt, solved to 1e-6
//          from zero by PCG with block-Jacobi, with edgefem's smoothed
//          aggregation (fine level assembled here) and with hypre's
//          BoomerAMG (systems AMG, 3 functions, nodal coarsening) on the same
//          matrix; memory of each preconditioner against the per-edge K's;
//          the SA's whole build, rebuild and refresh, in turn each round.
//  run     runs of --rounds steps of block-Jacobi, the lagged AMG and `auto`
//          (the default), a step of each in turn: mean ms per step.
// Medians over rounds; serial (one thread). Usage:
//   edgefem_bench_solvers [--meshes beam,bunny-4k] [--dts 1,4,10] [--rounds 9] [--parts direct,step,matrix,run]
//                         [--amg-smoother chebyshev|l1] [--amg-smoothing N] [--amg-coarse DOFS]
//                         [--amg-levels N] [--amg-ratio R] [--amg-weight W] [--amg-strength S] [--no-hypre] [--quick]
//                         [--threads N]  (the step part on the pool back-end's N threads; default serial)
//                         [--amg-only]   (the matrix part without block-Jacobi: the largest meshes)
//                         [--trace]      (the run part: each preconditioner's iterations, refreshes and ms per step, on stderr)
//                         [--no-retain]  (freed memory back to the system, glibc's defaults: edgefem/core/retain_freed_memory.hpp)
// (--amg-*: AmgSettings' fields, for the step and matrix parts, to study the
// hierarchy; unset ones keep SolverSettings' defaults)
#ifndef EDGEFEM_BENCH_HYPRE
#define EDGEFEM_BENCH_HYPRE 0
#endif
#if EDGEFEM_BENCH_HYPRE
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <mpi.h>
#endif

#include <dlfcn.h>

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/retain_freed_memory.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/smoothed_aggregation.hpp"
#include "edgefem/core/sparse_assembly.hpp"
#include "edgefem/core/sparse_cholesky.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/parallel/executors.hpp"
#include "lab/benchmark_scene.hpp"

using namespace edgefem;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Plain loops: Eigen's dense reductions trip g++ 12's false
// -Wmaybe-uninitialized with AVX-512 (GCC PR 105593).
double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    double s = 0;
    for (Eigen::Index i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}
double norm(const Eigen::VectorXd& a) { return std::sqrt(dot(a, a)); }

double median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

AmgSettings g_amg = SolverSettings{}.amg;  // the AMG's settings (--amg-*)
bool g_no_hypre = !EDGEFEM_BENCH_HYPRE;     // --no-hypre: the matrix part without BoomerAMG
int g_threads = 1;                          // --threads N: the step part on the pool back-end's N threads
std::vector<double> g_youngs;  // --youngs: Young's moduli to step each mesh at (empty: the scene's own)
bool g_trace = false;                       // --trace: the run part prints each preconditioner's iterations, refreshes and ms per step
bool g_amg_only = false;                    // --amg-only: the matrix part without block-Jacobi (large meshes)

std::string describe(const AmgSettings& a) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "AMG: %s smoother, %d step(s), coarsest <= %d dofs or a coarse level >= %g nonzero, <= %d levels, "
                  "Chebyshev ratio %g, prolongator weight %g, strength %g",
                  a.smoother == AmgSmoother::Chebyshev ? "Chebyshev" : "l1 block-Jacobi", a.smoothing_steps,
                  a.max_coarse_dofs, a.dense_coarsest, a.max_levels, a.chebyshev_ratio, a.prolongator_weight, a.strength);
    return buf;
}

// young > 0: every material's Young's modulus set to it (else the scene's).
Scene named_scene(const std::string& name, double young = 0) {
    Scene s = name == "beam" ? default_scene() : step_benchmark_scene(bench::bench_mesh(name), Material{1e5, 0.3, 1000});
    if (young > 0) {
        s.materials.fallback.young = young;
        for (auto& [region, mat] : s.materials.by_region) mat.young = young;
    }
    return s;
}

void for_solve(Scene& s, double dt_ms, PreconditionerKind pc) {
    s.dt = dt_ms * 1e-3;
    s.solver.cg_fixed_iterations = 0;
    s.solver.cg_tolerance = 1e-6;
    s.solver.cg_max_iterations = 20000;
    s.solver.preconditioner = pc;
    s.solver.amg = g_amg;
    s.count_inverted_tets = false;
}

// The system of a semi-implicit step at the state `u`: A = M + dt^2 K on the
// free dofs (dof: the free numbering) or on all dofs (constrained rows and
// columns zero).
struct Assembled {
    std::vector<index_t> dof;
    Eigen::SparseMatrix<double> A;
    std::vector<std::uint8_t> free;
    std::vector<double> mass;
    double k_ms = 0, assembly_ms = 0;
};

Assembled assemble_at(const Scene& s, ElasticOperator<double>& op, const std::vector<double>& u, bool all_dofs) {
    Assembled a;
    const std::size_t n = s.mesh.X.size();
    a.free.assign(n, 1);
    for (index_t v : s.fixed)
        for (int c = 0; c < 3; ++c) a.free[3 * std::size_t(v) + std::size_t(c)] = 0;
    std::vector<double> f(n);
    op.forces(u.data(), f.data(), false);
    auto t0 = Clock::now();
    op.build_stiffness(s.solver.definite_stiffness);
    a.k_ms = ms_since(t0);
    a.mass = lumped_mass(s.mesh, s.materials);
    const index_t nf = number_free_dofs(all_dofs ? std::vector<std::uint8_t>(n, 1) : a.free, a.dof);
    t0 = Clock::now();
    a.A = assemble_system<double>(a.dof, nf, 1.0, a.mass, {{s.dt * s.dt, &op}});
    a.assembly_ms = ms_since(t0);
    if (all_dofs)
        for (int k = 0; k < a.A.outerSize(); ++k)
            for (Eigen::SparseMatrix<double>::InnerIterator it(a.A, k); it; ++it)
                if (!a.free[std::size_t(it.row())] || !a.free[std::size_t(it.col())]) it.valueRef() = 0;
    return a;
}

// The displacement after `steps` CG steps of s.
std::vector<double> state_after(Scene s, int steps) {
    s.solver.preconditioner = PreconditionerKind::BlockJacobi;
    Simulator<double> sim(std::move(s), nullptr, cpu_operator_factory<double>());
    for (int k = 0; k < steps; ++k) sim.step();
    const auto u = sim.displacement();
    return {u.begin(), u.end()};
}

LowerCsc lower_of(const Eigen::SparseMatrix<double>& A) {
    const Eigen::SparseMatrix<double> L = A.triangularView<Eigen::Lower>();
    LowerCsc out;
    out.n = index_t(A.rows());
    out.col_start.assign(L.outerIndexPtr(), L.outerIndexPtr() + L.cols() + 1);
    out.row.assign(L.innerIndexPtr(), L.innerIndexPtr() + L.nonZeros());
    out.value.assign(L.valuePtr(), L.valuePtr() + L.nonZeros());
    return out;
}

// The file the BLAS that CHOLMOD calls was loaded from (Debian's
// libblas.so.3 alternative: reference BLAS or OpenBLAS), so that a figure
// says which BLAS produced it.
std::string blas_library() {
    void* dgemm = dlsym(RTLD_DEFAULT, "dgemm_");
    Dl_info info{};
    if (dgemm == nullptr || dladdr(dgemm, &info) == 0 || info.dli_fname == nullptr) return "unknown";
    char* real = realpath(info.dli_fname, nullptr);  // through the alternatives' links
    std::string path = real != nullptr ? real : info.dli_fname;
    std::free(real);
    // OpenBLAS's kernels: on a CPU it does not recognise (a VM's plain
    // "Intel Xeon Processor") it falls back to slow generic ones, 3x here
    // (docs/solvers.md, "Direct solver"); OPENBLAS_CORETYPE overrides.
    using CoreName = char* (*)();
    if (auto core = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename")))
        path += std::string(" (OpenBLAS kernels: ") + core() + ")";
    return path;
}


void bench_direct(int rounds) {
    Scene s = default_scene();
    for_solve(s, 1, PreconditionerKind::BlockJacobi);
    const std::vector<double> u = state_after(s, 5);
    auto op = cpu_operator_factory<double>()(s.mesh, s.materials, s.model, s.method);
    Assembled a = assemble_at(s, *op, u, false);
    std::printf("\n## direct: built-in beam, %ld free dofs, %ld stored entries (A = M + dt^2 K after 5 steps)\n\n"
                "BLAS: %s\n\n",
                long(a.A.rows()), long(a.A.nonZeros()), blas_library().c_str());
    SparseCholesky chol;
    auto t0 = Clock::now();
    chol.factor(lower_of(a.A));
    const double first = ms_since(t0);
    std::vector<double> eig, chm, eig_solve, chm_solve, eig_setup, chm_setup;
    Eigen::VectorXd b = Eigen::VectorXd::Ones(a.A.rows()), x(a.A.rows());
    double diff = 0;
    for (int r = 0; r < rounds; ++r) {
        // old path, per step: K, triplet assembly, SimplicialLDLT (analysis + factorisation)
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
        t0 = Clock::now();
        ldlt.compute(a.A);
        eig.push_back(ms_since(t0));
        t0 = Clock::now();
        const Eigen::VectorXd xe = ldlt.solve(b);
        eig_solve.push_back(ms_since(t0));
        Assembled again = assemble_at(s, *op, u, false);
        eig_setup.push_back(again.k_ms + again.assembly_ms + eig.back());
        // new: the numeric factorisation on the analysis kept
        const LowerCsc L = lower_of(a.A);
        t0 = Clock::now();
        chol.factor(L);
        chm.push_back(ms_since(t0));
        t0 = Clock::now();
        chol.solve(b.data(), x.data());
        chm_solve.push_back(ms_since(t0));
        diff = std::max(diff, norm(x - xe) / norm(xe));
    }
    // the new path's per-step set-up inside the simulator: K, assembly into the kept pattern, factorisation
    Scene sd = s;
    sd.solver.linear_solver = LinearSolver::Direct;
    Simulator<double> sim(sd, nullptr, cpu_operator_factory<double>());
    std::vector<double> step_ms, setup_ms;
    for (int k = 0; k < rounds + 2; ++k) {
        t0 = Clock::now();
        const StepStats& st = sim.step();
        if (k < 2) continue;
        step_ms.push_back(ms_since(t0));
        setup_ms.push_back(st.stiffness_ms);
    }
    std::printf("| path | factorisation ms | solve ms | set-up per step ms (K + assembly + factorisation) |\n");
    std::printf("|---|---:|---:|---:|\n");
    std::printf("| Eigen SimplicialLDLT (old) | %.1f | %.2f | %.1f |\n", median(eig), median(eig_solve), median(eig_setup));
    std::printf("| CHOLMOD supernodal LL^T, analysis kept (new) | %.2f | %.2f | %.1f |\n", median(chm),
                median(chm_solve), median(setup_ms));
    std::printf("\nCHOLMOD's first call (analysis + factorisation): %.1f ms; factor nonzeros %.3g; "
                "factorisation ratio old / new: %.1fx; set-up ratio: %.1fx; solutions agree to %.1e; "
                "new direct step (simulator, median): %.1f ms\n",
                first, chol.factor_nonzeros(), median(eig) / median(chm), median(eig_setup) / median(setup_ms), diff,
                median(step_ms));
}

void bench_steps(const std::vector<std::string>& meshes, const std::vector<double>& dts, int rounds) {
    const std::shared_ptr<const Executor> ex = g_threads > 1 ? make_executor(ExecutorKind::Pool, g_threads) : nullptr;
    std::printf("\n## step: semi-implicit, CG to 1e-6, %s; medians of %d alternating steps (after one)\n\n"
                "AMG: its Galerkin operators refreshed at every K (`amg_refresh_interval` 1) or lagged (0, the "
                "default: refreshed when the iterations per decade grow 1.5x).\n\n",
                ex ? ("pool x" + std::to_string(g_threads)).c_str() : "serial", rounds);
    std::printf("| mesh | dofs | Y Pa | dt ms | BJ its | AMG its (every K / lagged) | BJ ms/step | AMG ms/step (every K / lagged) | "
                "lagged AMG / BJ | direct ms/step | direct / BJ | BJ set-up ms | AMG set-up ms (every K / lagged) | "
                "AMG first step ms |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const std::vector<double> own{0.0};
    for (const std::string& m : meshes)
        for (double young : g_youngs.empty() ? own : g_youngs)
        for (double dt : dts) {
            const Scene s = named_scene(m, young);
            Scene sb = s, sa = s, sl = s, sd = s;
            for_solve(sb, dt, PreconditionerKind::BlockJacobi);
            for_solve(sd, dt, PreconditionerKind::BlockJacobi);
            sd.solver.linear_solver = LinearSolver::Direct;
            for_solve(sa, dt, PreconditionerKind::Amg);
            for_solve(sl, dt, PreconditionerKind::Amg);
            sa.solver.amg_refresh_interval = 1;
            sl.solver.amg_refresh_interval = 0;
            // A step can fail (the semi-implicit step is unstable on StVK at
            // large steps: the energy guard stops it): the row says so.
            try {
                Simulator<double> bj(sb, ex, cpu_operator_factory<double>());
                Simulator<double> amg(sa, ex, cpu_operator_factory<double>());
                Simulator<double> lag(sl, ex, cpu_operator_factory<double>());
                Simulator<double> direct(sd, ex, cpu_operator_factory<double>());
                bj.step();
                lag.step();
                direct.step();
                auto t0 = Clock::now();
                amg.step();
                const double first = ms_since(t0);
                std::vector<double> ms[4], its[4], setup[4];
                for (int r = 0; r < rounds; ++r)
                    for (int k = 0; k < 4; ++k) {
                        Simulator<double>& sim = k == 0 ? bj : k == 1 ? amg : k == 2 ? lag : direct;
                        t0 = Clock::now();
                        const StepStats& st = sim.step();
                        ms[k].push_back(ms_since(t0));
                        its[k].push_back(st.solver_iterations);
                        setup[k].push_back(st.stiffness_ms);
                    }
                std::printf("| %s | %zu | %g | %g | %.0f | %.0f / %.0f | %.2f | %.2f / %.2f | %.2f | %.2f | %.2f | %.2f | "
                            "%.2f / %.2f | %.1f |\n",
                            m.c_str(), s.mesh.X.size(), s.materials.fallback.young, dt, median(its[0]), median(its[1]), median(its[2]), median(ms[0]),
                            median(ms[1]), median(ms[2]), median(ms[2]) / median(ms[0]), median(ms[3]),
                            median(ms[3]) / median(ms[0]), median(setup[0]), median(setup[1]), median(setup[2]), first);
            } catch (const SimulationError& e) {
                std::printf("| %s | %zu | %g | %g | failed: %s |  |  |  |  |  |  |  |  |  |\n", m.c_str(), s.mesh.X.size(),
                            s.materials.fallback.young, dt, std::string(e.what()).substr(0, 90).c_str());
            }
            std::fflush(stdout);
        }
}

// Runs of `steps` semi-implicit steps (after one) of block-Jacobi, the lagged
// AMG and `auto`, a step of each in turn: the mean time per step (a lagged
// preconditioner's refreshes are periodic costs a median would hide), the
// CG iterations and AMG refreshes per step.
void bench_runs(const std::vector<std::string>& meshes, const std::vector<double>& dts, int steps) {
    const std::shared_ptr<const Executor> ex = g_threads > 1 ? make_executor(ExecutorKind::Pool, g_threads) : nullptr;
    std::printf("\n## run: semi-implicit, CG to 1e-6, %s; means over %d steps after the first, a step of each in turn\n\n",
                ex ? ("pool x" + std::to_string(g_threads)).c_str() : "serial", steps);
    std::printf("| mesh | Y Pa | dt ms | BJ its | AMG its | auto its | AMG refreshes | auto refreshes | BJ ms/step | "
                "AMG ms/step | auto ms/step | AMG / BJ | auto / BJ | auto / best |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    const std::vector<double> own{0.0};
    const PreconditionerKind kinds[3] = {PreconditionerKind::BlockJacobi, PreconditionerKind::Amg, PreconditionerKind::Auto};
    for (const std::string& m : meshes)
        for (double young : g_youngs.empty() ? own : g_youngs)
            for (double dt : dts) {
                const Scene s = named_scene(m, young);
                try {
                    std::vector<std::unique_ptr<Simulator<double>>> sim;
                    for (PreconditionerKind k : kinds) {
                        Scene sk = s;
                        for_solve(sk, dt, k);
                        sim.push_back(std::make_unique<Simulator<double>>(sk, ex, cpu_operator_factory<double>()));
                        sim.back()->step();
                    }
                    double ms[3] = {0, 0, 0}, its[3] = {0, 0, 0}, refreshes[3] = {0, 0, 0};
                    for (int r = 0; r < steps; ++r) {
                        int step_its[3], step_refreshes[3];
                        double step_ms[3];
                        for (int k = 0; k < 3; ++k) {
                            const auto t0 = Clock::now();
                            const StepStats& st = sim[std::size_t(k)]->step();
                            step_ms[k] = ms_since(t0);
                            ms[k] += step_ms[k] / steps;
                            its[k] += double(st.solver_iterations) / steps;
                            refreshes[k] += st.preconditioner_refreshes;
                            step_its[k] = st.solver_iterations;
                            step_refreshes[k] = st.preconditioner_refreshes;
                        }
                        if (g_trace)
                            std::fprintf(stderr, "%s Y %g dt %g step %d: BJ %d its %.2f ms, AMG %d its %d refreshes %.2f ms, auto %d its %d "
                                         "refreshes %.2f ms\n",
                                         m.c_str(), s.materials.fallback.young, dt, r + 2, step_its[0], step_ms[0],
                                         step_its[1], step_refreshes[1], step_ms[1], step_its[2], step_refreshes[2],
                                         step_ms[2]);
                    }
                    std::printf("| %s | %g | %g | %.1f | %.1f | %.1f | %.0f | %.0f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                                m.c_str(), s.materials.fallback.young, dt, its[0], its[1], its[2], refreshes[1],
                                refreshes[2], ms[0], ms[1], ms[2], ms[1] / ms[0], ms[2] / ms[0],
                                ms[2] / std::min(ms[0], ms[1]));
                } catch (const SimulationError& e) {
                    std::printf("| %s | %g | %g | failed: %s |  |  |  |  |  |  |  |  |  |  |\n", m.c_str(),
                                s.materials.fallback.young, dt, std::string(e.what()).substr(0, 90).c_str());
                }
                std::fflush(stdout);
            }
}

// PCG on an assembled matrix (free dofs where `keep` is 1), from zero, to
// `tol` relative residual; M: z = M^-1 r.
int pcg(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, Eigen::VectorXd& x, double tol,
        const std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>& M) {
    x.setZero(b.size());
    Eigen::VectorXd r = b, z(b.size()), p, Ap;
    M(r, z);
    p = z;
    double rz = dot(r, z);
    const double bn = norm(b);
    for (int it = 1; it <= 20000; ++it) {
        Ap = A * p;
        const double alpha = rz / dot(p, Ap);
        x += alpha * p;
        r -= alpha * Ap;
        if (norm(r) <= tol * bn) return it;
        M(r, z);
        const double rz2 = dot(r, z);
        p = z + (rz2 / rz) * p;
        rz = rz2;
    }
    return -1;
}

struct HypreResult {
    int iterations = 0;
    double setup_ms = 0, solve_ms = 0, residual = 0;
};

#if EDGEFEM_BENCH_HYPRE
// hypre BoomerAMG-preconditioned PCG on A (free dofs), systems AMG with 3
// functions (unknown approach) and nodal coarsening.
HypreResult hypre_solve(const Eigen::SparseMatrix<double, Eigen::RowMajor>& A, const Eigen::VectorXd& b,
                        Eigen::VectorXd& x) {
    const int n = int(A.rows());
    HYPRE_IJMatrix ij;
    HYPRE_IJMatrixCreate(MPI_COMM_WORLD, 0, n - 1, 0, n - 1, &ij);
    HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR);
    HYPRE_IJMatrixInitialize(ij);
    for (int i = 0; i < n; ++i) {
        std::vector<HYPRE_Int> cols;
        std::vector<double> vals;
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(A, i); it; ++it) {
            cols.push_back(HYPRE_Int(it.col()));
            vals.push_back(it.value());
        }
        HYPRE_Int nc = HYPRE_Int(cols.size()), row = i;
        HYPRE_IJMatrixSetValues(ij, 1, &nc, &row, cols.data(), vals.data());
    }
    HYPRE_IJMatrixAssemble(ij);
    HYPRE_ParCSRMatrix par;
    HYPRE_IJMatrixGetObject(ij, reinterpret_cast<void**>(&par));
    const auto vec = [&](const double* v, HYPRE_IJVector& iv) {
        HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, n - 1, &iv);
        HYPRE_IJVectorSetObjectType(iv, HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(iv);
        std::vector<HYPRE_Int> idx(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) idx[std::size_t(i)] = i;
        HYPRE_IJVectorSetValues(iv, n, idx.data(), v);
        HYPRE_IJVectorAssemble(iv);
    };
    HYPRE_IJVector ib, ix;
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    vec(b.data(), ib);
    vec(zero.data(), ix);
    HYPRE_ParVector pb, px;
    HYPRE_IJVectorGetObject(ib, reinterpret_cast<void**>(&pb));
    HYPRE_IJVectorGetObject(ix, reinterpret_cast<void**>(&px));
    HYPRE_Solver solver, amg;
    HYPRE_ParCSRPCGCreate(MPI_COMM_WORLD, &solver);
    HYPRE_PCGSetTol(solver, 1e-6);
    HYPRE_PCGSetMaxIter(solver, 20000);
    HYPRE_PCGSetTwoNorm(solver, 1);
    HYPRE_BoomerAMGCreate(&amg);
    HYPRE_BoomerAMGSetNumFunctions(amg, 3);
    HYPRE_BoomerAMGSetNodal(amg, 4);
    HYPRE_BoomerAMGSetStrongThreshold(amg, 0.5);
    HYPRE_BoomerAMGSetCoarsenType(amg, 10);  // HMIS
    HYPRE_BoomerAMGSetInterpType(amg, 6);    // extended+i
    HYPRE_BoomerAMGSetPMaxElmts(amg, 4);
    HYPRE_BoomerAMGSetRelaxType(amg, 8);     // l1 symmetric Gauss-Seidel
    HYPRE_BoomerAMGSetMaxIter(amg, 1);
    HYPRE_BoomerAMGSetTol(amg, 0.0);
    HYPRE_BoomerAMGSetPrintLevel(amg, 0);
    HYPRE_PCGSetPrecond(solver, reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSolve),
                        reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSetup), amg);
    HypreResult res;
    auto t0 = Clock::now();
    HYPRE_ParCSRPCGSetup(solver, par, pb, px);
    res.setup_ms = ms_since(t0);
    t0 = Clock::now();
    HYPRE_ParCSRPCGSolve(solver, par, pb, px);
    res.solve_ms = ms_since(t0);
    HYPRE_Int its = 0;
    HYPRE_PCGGetNumIterations(solver, &its);
    res.iterations = int(its);
    HYPRE_PCGGetFinalRelativeResidualNorm(solver, &res.residual);
    x.resize(n);
    std::vector<HYPRE_Int> idx(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) idx[std::size_t(i)] = i;
    HYPRE_IJVectorGetValues(ix, n, idx.data(), x.data());
    HYPRE_BoomerAMGDestroy(amg);
    HYPRE_ParCSRPCGDestroy(solver);
    HYPRE_IJVectorDestroy(ib);
    HYPRE_IJVectorDestroy(ix);
    HYPRE_IJMatrixDestroy(ij);
    return res;
}
#else
// Built without hypre (EDGEFEM_BENCH_HYPRE=OFF): g_no_hypre is always set.
HypreResult hypre_solve(const Eigen::SparseMatrix<double, Eigen::RowMajor>&, const Eigen::VectorXd&, Eigen::VectorXd&) {
    std::abort();
}
#endif

void bench_matrix(const std::vector<std::string>& meshes, const std::vector<double>& dts, int rounds) {
    std::printf("\n## matrix: one assembled A = M + dt^2 K (after 3 steps), PCG from 0 to 1e-6, serial; medians of %d\n\n",
                rounds);
    std::printf("| mesh | dt ms | preconditioner | its | set-up ms | solve ms | total ms | memory / per-edge K |\n");
    std::printf("|---|---:|---|---:|---:|---:|---:|---:|\n");
    for (const std::string& m : meshes)
        for (double dt : dts) {
            Scene s = named_scene(m);
            // --amg-only: the 3 steps to the test state with AMG too (block-
            // Jacobi's take tens of minutes on bunny-1m at 10 ms)
            for_solve(s, dt, g_amg_only ? PreconditionerKind::Amg : PreconditionerKind::BlockJacobi);
            const std::vector<double> u = state_after(s, 3);
            auto op = cpu_operator_factory<double>()(s.mesh, s.materials, s.model, s.method);
            const Assembled all = assemble_at(s, *op, u, true);
            const SparseRows A = all.A;
            const std::size_t n = s.mesh.X.size(), nv = n / 3;
            // the load: gravity on the free dofs
            Eigen::VectorXd b = Eigen::VectorXd::Zero(Eigen::Index(n));
            for (std::size_t v = 0; v < nv; ++v)
                if (all.free[3 * v + 2]) b[Eigen::Index(3 * v + 2)] = -9.81 * all.mass[v] * s.dt;
            // per-edge K: 9 doubles per edge + 9 per vertex (diagonal)
            const double blocks = double(A.nonZeros()) / 9.0;  // 2 #E + #V stored 3x3 blocks
            const double edges = (blocks - double(nv)) / 2;
            const double k_bytes = 8.0 * 9.0 * (edges + double(nv));
            // block-Jacobi
            std::vector<double> its_bj, t_bj, setup_bj;
            Eigen::VectorXd x;
            std::vector<Eigen::Matrix3d> Dinv(nv);
            const auto bj_setup = [&] {
                for (std::size_t v = 0; v < nv; ++v) {
                    Eigen::Matrix3d D;
                    for (int r = 0; r < 3; ++r)
                        for (int c = 0; c < 3; ++c) {
                            const bool live = all.free[3 * v + std::size_t(r)] && all.free[3 * v + std::size_t(c)];
                            D(r, c) = live ? A.coeff(Eigen::Index(3 * v) + r, Eigen::Index(3 * v) + c) : double(r == c);
                        }
                    Dinv[v] = D.inverse();
                }
            };
            const auto bj_apply = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
                z.resize(r.size());
                for (std::size_t v = 0; v < nv; ++v) z.segment<3>(Eigen::Index(3 * v)) = Dinv[v] * r.segment<3>(Eigen::Index(3 * v));
                for (std::size_t i = 0; i < n; ++i)
                    if (!all.free[i]) z[Eigen::Index(i)] = 0;
            };
            // smoothed aggregation on the same matrix (fine level assembled)
            SmoothedAggregation sa;
            std::vector<double> its_sa, t_sa, setup_sa, refresh_sa, build_sa, rebuild_sa;
            const auto fine = [&](const double* in, double* out) {
                Eigen::Map<Eigen::VectorXd>(out, Eigen::Index(n)) = A * Eigen::Map<const Eigen::VectorXd>(in, Eigen::Index(n));
            };
            const auto sa_apply = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
                z.resize(r.size());
                sa.apply(r.data(), z.data(), fine);
            };
            // hypre on the free dofs
            std::vector<index_t> dof;
            const index_t nf = number_free_dofs(all.free, dof);
            Eigen::SparseMatrix<double, Eigen::RowMajor> Af = assemble_system<double>(dof, nf, 1.0, all.mass, {{s.dt * s.dt, op.get()}});
            Eigen::VectorXd bf(nf);
            for (std::size_t i = 0; i < n; ++i)
                if (dof[i] >= 0) bf[dof[i]] = b[Eigen::Index(i)];
            std::vector<double> its_h, t_h, setup_h;
            double x_diff = 0;
            Eigen::VectorXd x_bj, x_sa, x_h;
            for (int r = 0; r < rounds; ++r) {
                auto t0 = Clock::now();
                if (!g_amg_only) {
                    bj_setup();
                    setup_bj.push_back(ms_since(t0));
                    t0 = Clock::now();
                    its_bj.push_back(pcg(A, b, x_bj, 1e-6, bj_apply));
                    t_bj.push_back(ms_since(t0));
                }
                t0 = Clock::now();
                if (r == 0) {
                    sa.build(A, s.mesh.X, all.free, g_amg);
                    sa.release_build_data();  // as the simulator's preconditioner
                } else {
                    // a whole build (a fresh object), a rebuild (the first
                    // build's aggregates and patterns) and a refresh in turn
                    SmoothedAggregation sb;
                    sb.build(A, s.mesh.X, all.free, g_amg);
                    sb.release_build_data();
                    build_sa.push_back(ms_since(t0));
                    t0 = Clock::now();
                    sa.rebuild(A, s.mesh.X);
                    rebuild_sa.push_back(ms_since(t0));
                    t0 = Clock::now();
                    sa.refresh(A);
                }
                (r == 0 ? setup_sa : refresh_sa).push_back(ms_since(t0));
                t0 = Clock::now();
                its_sa.push_back(pcg(A, b, x_sa, 1e-6, sa_apply));
                t_sa.push_back(ms_since(t0));
                if (g_no_hypre) continue;
                const HypreResult h = hypre_solve(Af, bf, x_h);
                its_h.push_back(h.iterations);
                setup_h.push_back(h.setup_ms);
                t_h.push_back(h.solve_ms);
            }
            double x_max = 0;
            for (std::size_t i = 0; i < n; ++i) x_max = std::max(x_max, std::abs(x_sa[Eigen::Index(i)]));
            for (std::size_t i = 0; i < n && !g_no_hypre; ++i)
                if (dof[i] >= 0) x_diff = std::max(x_diff, std::abs(x_h[dof[i]] - x_sa[Eigen::Index(i)]) / x_max);
            // + the vertex-block pattern the simulator keeps to assemble A at a
            // refresh (its values and the projected copy are freed in between)
            const double sa_bytes = double(sa.bytes()) + 4.0 * (blocks + double(nv) + 1);
            const double refresh = refresh_sa.empty() ? NAN : median(refresh_sa);
            if (!g_amg_only)
                std::printf("| %s | %g | block-Jacobi | %.0f | %.2f | %.2f | %.2f | %.2f |\n", m.c_str(), dt,
                            median(its_bj), median(setup_bj), median(t_bj), median(setup_bj) + median(t_bj),
                            8.0 * 18 * double(nv) / k_bytes);
            std::printf("| %s | %g | edgefem SA-AMG (%d levels; build %.1f, refresh) | %.0f | %.2f | %.2f | %.2f | %.2f |\n",
                        m.c_str(), dt, sa.levels(), setup_sa[0], median(its_sa), refresh, median(t_sa),
                        refresh + median(t_sa), sa_bytes / k_bytes);
            std::printf("|  |  | (hierarchy: dofs, P entries per fine row, A entries per row:");
            for (int l = 0; l < sa.levels(); ++l) {
                std::printf(" L%d %ld", l, long(sa.dofs(l)));
                if (l + 1 < sa.levels()) std::printf(" P %.1f", double(sa.prolongator(l).nonZeros()) / double(sa.dofs(l)));
                if (l > 0 && l + 1 < sa.levels()) std::printf(" A %.1f", double(sa.matrix(l).nonZeros()) / double(sa.dofs(l)));
            }
            std::printf("; a V-cycle costs %.2f fine products) |  |  |  |  |  |\n", sa.cycle_cost());
            if (!refresh_sa.empty())
                std::printf("|  |  | (medians over %zu rounds: a whole build %.2f ms, a rebuild %.2f, a refresh %.2f; "
                            "build/refresh %.2f, rebuild/refresh %.2f) |  |  |  |  |  |\n",
                            refresh_sa.size(), median(build_sa), median(rebuild_sa), refresh, median(build_sa) / refresh,
                            median(rebuild_sa) / refresh);
            if (!g_no_hypre) {
                std::printf("| %s | %g | hypre BoomerAMG (systems, nodal) | %.0f | %.2f | %.2f | %.2f | - |\n", m.c_str(),
                            dt, median(its_h), median(setup_h), median(t_h), median(setup_h) + median(t_h));
                std::printf("|  |  | (hypre and SA solutions differ by %.1e of max) |  |  |  |  |  |\n", x_diff);
            }
            std::fflush(stdout);
        }
}

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> meshes{"beam", "bunny-4k"};
    std::vector<double> dts{1, 4, 10};
    int rounds = 9;
    std::string parts = "direct,step,matrix";
    bool retain = true;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "edgefem_bench_solvers: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--meshes") meshes = split(next());
        else if (a == "--dts") {
            dts.clear();
            for (const std::string& d : split(next())) dts.push_back(std::stod(d));
        } else if (a == "--rounds") rounds = std::max(1, std::stoi(next()));
        else if (a == "--parts") parts = next();
        else if (a == "--amg-smoothing") g_amg.smoothing_steps = std::max(1, std::stoi(next()));
        else if (a == "--amg-coarse") g_amg.max_coarse_dofs = std::max(1, std::stoi(next()));
        else if (a == "--amg-dense") g_amg.dense_coarsest = std::stod(next());
        else if (a == "--youngs") {
            for (const std::string& y : split(next())) g_youngs.push_back(std::stod(y));
        }
        else if (a == "--no-hypre") g_no_hypre = true;
        else if (a == "--no-retain") retain = false;
        else if (a == "--threads") g_threads = std::max(1, std::stoi(next()));
        else if (a == "--amg-only") g_amg_only = true;
        else if (a == "--trace") g_trace = true;
        else if (a == "--amg-levels") g_amg.max_levels = std::max(1, std::stoi(next()));
        else if (a == "--amg-ratio") g_amg.chebyshev_ratio = std::stod(next());
        else if (a == "--amg-weight") g_amg.prolongator_weight = std::stod(next());
        else if (a == "--amg-strength") g_amg.strength = std::stod(next());
        else if (a == "--amg-smoother") {
            const std::string k = next();
            if (k != "chebyshev" && k != "l1") {
                std::fprintf(stderr, "edgefem_bench_solvers: --amg-smoother must be chebyshev or l1, not %s\n", k.c_str());
                return 2;
            }
            g_amg.smoother = k == "chebyshev" ? AmgSmoother::Chebyshev : AmgSmoother::L1Jacobi;
        }
        else if (a == "--quick") {
            meshes = {"box-1200"};
            dts = {4};
            rounds = 1;
            parts = "step,matrix";
        } else {
            std::fprintf(stderr, "edgefem_bench_solvers: unknown argument %s\n", a.c_str());
            return 2;
        }
    }
    std::printf("%s\n", describe(g_amg).c_str());
    // As the edgefem program does: the AMG's refreshes reuse freed memory
    // instead of faulting fresh pages in (--no-retain: glibc's defaults).
    const bool retained = retain && edgefem::retain_freed_memory();
    std::printf("freed memory %s (edgefem/core/retain_freed_memory.hpp)\n",
                retained ? "kept for reuse" : "returned to the system (glibc's defaults)");
    if (parts.find("direct") != std::string::npos) bench_direct(rounds);
    if (parts.find("step") != std::string::npos) bench_steps(meshes, dts, rounds);
    if (parts.find("run") != std::string::npos) bench_runs(meshes, dts, rounds);
    if (parts.find("matrix") != std::string::npos) {
#if EDGEFEM_BENCH_HYPRE
        // MPI (hypre's) only here: its singleton start leaves a helper process running.
        MPI_Init(&argc, &argv);
        bench_matrix(meshes, dts, rounds);
        HYPRE_Finalize();
        MPI_Finalize();
#else
        bench_matrix(meshes, dts, rounds);
#endif
    }
    return 0;
}
