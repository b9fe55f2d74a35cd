// Parallel back-ends: force, stiffness and K x of the edge-based FE model
// (double, twist configuration) and a whole semi-implicit step, for
// back-end x variant x threads, plus a STREAM-like triad for the memory
// bandwidth of the same run. Threads: 1, 2, 4, ... up to the cores present
// (and that count itself); $EDGEFEM_BENCH_THREADS="1,3,16" overrides.
// Names: <kernel>/<backend>/<variant>/<threads>/<mesh>; "serial/core" is
// core's serial loops (the reference). The step (kernel "step") is
// bench_step's scene: h = 1 ms, gravity, the lowest 1% fixed, 20
// warm-started CG iterations; "step/serial/core" is the serial Simulator.
// "cg/<backend>/core/<threads>/<mesh>": CG's vector work alone (20
// iterations on a diagonal system of the mesh's 3 #V dofs; counter
// per_iteration). Back-ends: OpenMP, oneTBB and the pool.
// Counters: per_tet (s per tet, shown as ns), bytes (compulsory bytes moved per call, force kernel only) and
// bytes_per_second; times are wall-clock (UseRealTime). Every mesh is
// renumbered by reverse Cuthill-McKee first (partition/), the locality
// ordering the blocked colourings and the owner variant's parts rely on
// (with the input numbering of the shared meshes the owner variant's spill
// windows cover 1.6-37x the vertices); all rows see the same numbering.
// The stiffness is the default tet-local layout (core/tet_edge_form.hpp) in
// core's serial loop and in every variant (owner: owner parts of the form's
// batches; the others: a coloured scatter over them; the variant decides the
// per-edge terms). The FE force of core's serial loop and of the owner
// variant takes g from the form too ($EDGEFEM_FORM_FORCES=0: the TSEP loop).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <sstream>

#include "bench_meshes.hpp"
#include "lab/benchmark_scene.hpp"
#include "edgefem/core/cg.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/cpu_operator.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "lab/stream_bandwidth.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

enum class Kernel { Force, Stiffness, Kx };
const char* name_of(Kernel k) { return k == Kernel::Force ? "force" : k == Kernel::Stiffness ? "stiffness" : "kx"; }

struct Prepared {
    std::string name;
    Mesh mesh;  // RCM-renumbered
    EdgeModel<double> model;
    TetEdgeForm<double> form;
    std::vector<double> u, x;
};

// One mesh at a time (bunny-1m's model is ~0.4 GB).
Prepared& prepared(const std::string& name) {
    static std::unique_ptr<Prepared> p;
    if (!p || p->name != name) {
        p.reset();
        p = std::make_unique<Prepared>();
        p->name = name;
        p->mesh = permute_mesh(bench::bench_mesh(name), vertex_ordering(bench::bench_mesh(name), Ordering::RCM));
        const Mesh& mesh = p->mesh;
        const Topology topo = build_topology(mesh);
        const Materials mat(Material{1e5, 0.3, 1000});
        p->model = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
        p->form = make_tet_edge_form<double>(mesh, topo, mat);
        p->u = deformation_displacement(mesh, Deformation::Twist);
        p->x.resize(p->u.size());
        for (std::size_t i = 0; i < p->x.size(); ++i) p->x[i] = std::sin(0.7 * double(i));
    }
    return *p;
}

// Compulsory traffic of one FE force call, as `edgefem bench` counts it
// (stream_bandwidth.hpp, TrafficModel::Compulsory): every array once, the
// state (p~, zeta, g) written once and, unless the tet-local form runs in
// cache-sized tiles, read back once. `form`: g from the tet-local form.
double force_bytes(const Prepared& p, bool form) {
    return form ? form_force_bytes_per_call(p.model, p.form, TrafficModel::Compulsory)
                : force_bytes_per_call(p.model, ModelKind::FE, TrafficModel::Compulsory);
}

// $EDGEFEM_OWNER_PARTS: the owner variant's part count (default: a
// function of #V, variant.hpp), for studies of its balance at many threads.
// $EDGEFEM_FORM_FORCES=0: the FE forces take g from the variant's TSEP loop
// instead of the tet-local form (PlanOptions::form_forces).
PlanOptions plan_options() {
    PlanOptions o;
    if (const char* env = std::getenv("EDGEFEM_FORM_FORCES"); env && *env) o.form_forces = std::atoi(env) != 0;
    if (const char* env = std::getenv("EDGEFEM_OWNER_PARTS"); env && *env) {
        o.owner_parts = std::max(0, std::atoi(env));
        if (o.owner_parts == 0)
            std::fprintf(stderr, "EDGEFEM_OWNER_PARTS=%s is not a positive count; using the default\n", env);
    }
    return o;
}

// The kernels object of the current (mesh, backend, variant, threads),
// kept while consecutive benchmarks use it.
struct Current {
    std::string key;
    std::unique_ptr<ParallelEdgeKernels<double>> k;
};

ParallelEdgeKernels<double>& kernels(const std::string& mesh, Backend b, Variant v, int threads) {
    static Current cur;
    const std::string key = mesh + to_string(b) + to_string(v) + std::to_string(threads);
    if (cur.key != key) {
        cur.k.reset();
        const auto t0 = std::chrono::steady_clock::now();
        cur.k = std::make_unique<ParallelEdgeKernels<double>>(prepared(mesh).model, make_executor(b, threads), v,
                                                              plan_options(), prepared(mesh).form);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (v == Variant::Colour && b == Backend::OpenMP && threads == 1)
            std::fprintf(stderr, "%s colourings (plan %.2f s): vertex segments %s; tsep g %s; tsep K %s; tet-local K %s\n",
                         mesh.c_str(), s, cur.k->vertex_colouring().stats().describe().c_str(),
                         cur.k->tsep_colouring().stats().describe().c_str(),
                         cur.k->stiffness_colouring().stats().describe().c_str(),
                         cur.k->form_colouring().stats().describe().c_str());
        if (v == Variant::Owner && b == Backend::OpenMP && threads == 1) {
            const ForwardSpill &vs = cur.k->vertex_parts(), &es = cur.k->edge_parts();
            std::fprintf(stderr,
                         "%s owner parts: %d; spill windows %.1f%% of the vertices, %.1f%% of the edges; force "
                         "g corrected after the barrier on %.1f%% of the edges\n",
                         mesh.c_str(), int(vs.parts()), 100.0 * double(vs.spill_targets()) / std::max<index_t>(1, vs.items()),
                         100.0 * double(es.spill_targets()) / std::max<index_t>(1, es.items()),
                         100.0 * double(cur.k->corrected_edges()) / std::max<index_t>(1, es.items()));
            const auto& fb = cur.k->form_batch_parts();
            if (fb.size() > 1) {
                index_t lo = fb[1] - fb[0], hi = lo;
                for (std::size_t q = 1; q + 1 < fb.size(); ++q) {
                    lo = std::min(lo, fb[q + 1] - fb[q]);
                    hi = std::max(hi, fb[q + 1] - fb[q]);
                }
                std::fprintf(stderr, "%s owner parts of the tet-local form: %d to %d batches per part (of %d)\n",
                             mesh.c_str(), int(lo), int(hi), int(fb.back()));
            }
        }
        cur.key = key;
    }
    return *cur.k;
}

// `form`: the force takes g from the tet-local form.
void set_counters(benchmark::State& state, const Prepared& p, Kernel k, bool form) {
    state.counters["per_tet"] = benchmark::Counter(double(p.model.num_tets),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    if (k == Kernel::Force) {
        const double bytes = force_bytes(p, form);
        state.counters["bytes"] = bytes;
        state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
    }
}

void BM_Core(benchmark::State& state, std::string mesh, Kernel k) {
    const Prepared& p = prepared(mesh);
    std::vector<double> f(p.u.size()), y(p.u.size());
    EdgeState<double> st;
    EdgeStiffness<double> K;
    // The serial operator's force: g from the tet-local form unless
    // $EDGEFEM_FORM_FORCES=0 (then the fused TSEP loop).
    const bool form_forces = plan_options().form_forces;
    const auto force = [&] {
        if (form_forces)
            tet_form_forces<ModelKind::FE, false>(p.model, p.form, p.u.data(), f.data(), st);
        else
            edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
    };
    force();
    tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K);
    for (auto _ : state) {
        switch (k) {
            case Kernel::Force: force(); break;
            case Kernel::Stiffness: tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K); break;
            case Kernel::Kx: edge_multiply(p.model, K, p.x.data(), y.data()); break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
    set_counters(state, p, k, form_forces);
}

void BM_Parallel(benchmark::State& state, std::string mesh, Kernel k, Backend b, Variant v, int threads) {
    const Prepared& p = prepared(mesh);
    auto& kern = kernels(mesh, b, v, threads);
    std::vector<double> f(p.u.size()), y(p.u.size());
    EdgeState<double> st;
    EdgeStiffness<double> K;
    kern.forces<ModelKind::FE, false>(p.u.data(), f.data(), st);
    kern.stiffness<ModelKind::FE>(st, K);
    for (auto _ : state) {
        switch (k) {
            case Kernel::Force: kern.forces<ModelKind::FE, false>(p.u.data(), f.data(), st); break;
            case Kernel::Stiffness: kern.stiffness<ModelKind::FE>(st, K); break;
            case Kernel::Kx: kern.multiply(K, p.x.data(), y.data()); break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
    set_counters(state, p, k, kern.form_forces());
}

// One semi-implicit step (bench_step's scene, 20 warm-started CG
// iterations) on the RCM mesh: serial Simulator when `threads` is 0, else
// the Simulator on the back-end's executor with the variant's operator.
void BM_Step(benchmark::State& state, std::string mesh, Backend b, Variant v, int threads) {
    // Kept while consecutive runs (repetitions) use it: bunny-1m's set-up
    // takes seconds.
    static std::string key;
    static std::unique_ptr<Simulator<double>> sim;
    const std::string k = mesh + to_string(b) + to_string(v) + std::to_string(threads);
    if (key != k || !sim) {
        sim.reset();
        Scene scene = step_benchmark_scene(prepared(mesh).mesh, Material{1e5, 0.3, 1000});
        scene.solver.cg_fixed_iterations = 20;
        std::shared_ptr<const Executor> ex;
        OperatorFactory<double> factory;
        if (threads > 0) {
            ex = make_executor(b, threads);
            factory = cpu_operator_factory<double>({ex, v}, plan_options());
        }
        sim = std::make_unique<Simulator<double>>(std::move(scene), ex, factory);
        for (int i = 0; i < 3; ++i) sim->step();  // warm: K, buffers, a moving state
        key = k;
    }
    for (auto _ : state) sim->step();
    state.counters["per_tet"] = benchmark::Counter(double(prepared(mesh).model.num_tets),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// CG's vector work alone: 20 iterations on a diagonal system with as many
// dofs as the mesh's step (3 #V), so that the step rows' CG part can be
// told from the kernels' (Jacobi preconditioner, no product). Serial when
// `threads` is 0. On a small mesh this is mostly the cost of an
// iteration's two barriers and its call.
void BM_Cg(benchmark::State& state, std::string mesh, Backend b, int threads) {
    const std::size_t n = 3 * std::size_t(prepared(mesh).mesh.num_vertices());
    std::vector<double> d(n), rhs(n), x(n);
    std::vector<std::uint8_t> free_dof(n, 1);
    for (std::size_t i = 0; i < n; ++i) {
        d[i] = 1.0 + double(i % 7);
        rhs[i] = std::sin(0.3 * double(i));
    }
    const auto ex = threads > 0 ? make_executor(b, threads) : std::make_shared<SerialExecutor>();
    CgWork w;
    for (auto _ : state) {
        std::fill(x.begin(), x.end(), 0.0);
        const CgResult r = conjugate_gradient(
            *ex, n, free_dof.data(), [](const double*, double*) {},
            [&](std::size_t lo, std::size_t hi, const double* in, double* out) {
                for (std::size_t i = lo; i < hi; ++i) out[i] = d[i] * in[i];
            },
            [&](std::size_t lo, std::size_t hi, const double* r_in, double* z) {
                for (std::size_t i = lo; i < hi; ++i) z[i] = r_in[i] / d[i];
            },
            rhs.data(), x.data(), 0.0, 20, 20, w);
        benchmark::DoNotOptimize(r.residual);
    }
    state.counters["per_iteration"] =
        benchmark::Counter(20.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// 1, 2, 4, ... below the cores present, then that count; or the list in
// $EDGEFEM_BENCH_THREADS.
std::vector<int> thread_counts() {
    std::vector<int> out;
    if (const char* env = std::getenv("EDGEFEM_BENCH_THREADS"); env && *env) {
        std::stringstream ss(env);
        std::string item;
        while (std::getline(ss, item, ','))
            if (const int t = std::atoi(item.c_str()); t > 0) out.push_back(t);
        if (!out.empty()) return out;
        std::fprintf(stderr, "EDGEFEM_BENCH_THREADS=%s names no thread count; using the default\n", env);
    }
    const int cores = std::max(1, hardware_threads());
    for (int t = 1; t < cores; t *= 2) out.push_back(t);
    out.push_back(cores);
    if (out.size() == 1) out.push_back(2);  // one core: still show 2 threads
    return out;
}

// STREAM triad a = b + s c on arrays far larger than the caches, in the
// executor's fixed blocks; 24 bytes per element (no write-allocate counted,
// as STREAM does).
void BM_Triad(benchmark::State& state, int threads) {
    const std::size_t n = std::size_t(1) << 24;  // 3 x 128 MiB
    static std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
    const auto ex = make_executor(threads == 1 ? Backend::Serial : Backend::OpenMP, threads, Schedule::Static);
    const index_t chunks = 64 * std::max(1, threads);
    const std::size_t chunk = (n + chunks - 1) / chunks;
    const double s = 3.0;
    for (auto _ : state) {
        ex->for_chunks(chunks, [&](index_t k) {
            const std::size_t lo = std::size_t(k) * chunk, hi = std::min(n, lo + chunk);
            double* __restrict pa = a.data();
            const double* __restrict pb = b.data();
            const double* __restrict pc = c.data();
            for (std::size_t i = lo; i < hi; ++i) pa[i] = pb[i] + s * pc[i];
        });
        benchmark::DoNotOptimize(a.data());
        benchmark::ClobberMemory();
    }
    state.counters["bytes_per_second"] = benchmark::Counter(24.0 * double(n), benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    const std::vector<int> threads = thread_counts();
    for (int t : threads)
        benchmark::RegisterBenchmark(("triad/" + std::to_string(t)).c_str(), BM_Triad, t)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    for (const char* mesh : bench::kBenchMeshes) {
        for (Kernel k : {Kernel::Force, Kernel::Stiffness, Kernel::Kx})
            benchmark::RegisterBenchmark((std::string(name_of(k)) + "/serial/core/1/" + mesh).c_str(), BM_Core,
                                         std::string(mesh), k)
                ->Unit(benchmark::kMicrosecond)
                ->UseRealTime();
        benchmark::RegisterBenchmark((std::string("step/serial/core/1/") + mesh).c_str(), BM_Step, std::string(mesh),
                                     Backend::Serial, Variant::Auto, 0)
            ->Unit(benchmark::kMicrosecond)
            ->UseRealTime();
        benchmark::RegisterBenchmark((std::string("cg/serial/core/1/") + mesh).c_str(), BM_Cg, std::string(mesh),
                                     Backend::Serial, 0)
            ->Unit(benchmark::kMicrosecond)
            ->UseRealTime();
        for (Backend b : {Backend::OpenMP, Backend::TBB, Backend::Pool})
            for (int t : threads)
                benchmark::RegisterBenchmark(
                    (std::string("cg/") + to_string(b) + "/core/" + std::to_string(t) + "/" + mesh).c_str(), BM_Cg,
                    std::string(mesh), b, t)
                    ->Unit(benchmark::kMicrosecond)
                    ->UseRealTime();
        for (Backend b : {Backend::OpenMP, Backend::TBB, Backend::Pool})
            for (Variant v : kAllVariants)
                for (int t : threads) {
                    for (Kernel k : {Kernel::Force, Kernel::Stiffness, Kernel::Kx}) {
                        const std::string name = std::string(name_of(k)) + "/" + to_string(b) + "/" + to_string(v) +
                                                 "/" + std::to_string(t) + "/" + mesh;
                        benchmark::RegisterBenchmark(name.c_str(), BM_Parallel, std::string(mesh), k, b, v, t)
                            ->Unit(benchmark::kMicrosecond)
                            ->UseRealTime();
                    }
                    const std::string name = std::string("step/") + to_string(b) + "/" + to_string(v) + "/" + std::to_string(t) + "/" + mesh;
                    benchmark::RegisterBenchmark(name.c_str(), BM_Step, std::string(mesh), b, v, t)
                        ->Unit(benchmark::kMicrosecond)
                        ->UseRealTime();
                }
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
