// Parallel back-ends: force, stiffness and K x of the edge-based FE model
// (double, twist configuration) for back-end x variant x threads, plus a
// STREAM-like triad for the memory bandwidth of the same run.
// Names: <kernel>/<backend>/<variant>/<threads>/<mesh>; "serial/core" is
// core's serial loops (the reference). Counters: per_tet (s per tet, shown
// as ns), bytes (compulsory bytes moved per call, force kernel only) and
// bytes_per_second; times are wall-clock (UseRealTime). Every mesh is
// renumbered by reverse Cuthill-McKee first (partition/), the locality
// ordering the blocked colourings and the owner variant's parts rely on
// (with the input numbering of the shared meshes the owner variant's spill
// windows cover 1.6-37x the vertices); all rows see the same numbering.
// The stiffness is the default tet-local layout (core/tet_edge_form.hpp) in
// core's serial loop and in every variant (its pair terms are a coloured
// scatter over tet batches whatever the variant; the variant decides the
// per-edge terms only).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/deformations.hpp"
#include "edgefem/core/edge_kernels.hpp"
#include "edgefem/parallel/executors.hpp"
#include "edgefem/parallel/parallel_edge_kernels.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

enum class Kernel { Force, Stiffness, Kx };
const char* name_of(Kernel k) { return k == Kernel::Force ? "force" : k == Kernel::Stiffness ? "stiffness" : "kx"; }

struct Prepared {
    std::string name;
    EdgeModel<double> model;
    TetEdgeForm<double> form;
    std::vector<double> u, x;
};

// One mesh at a time (bunny-1m's model is ~0.4 GB).
Prepared& prepared(const std::string& name) {
    static std::unique_ptr<Prepared> p;
    if (!p || p->name != name) {
        p.reset();
        const Mesh mesh = permute_mesh(bench::bench_mesh(name), vertex_ordering(bench::bench_mesh(name), Ordering::RCM));
        const Topology topo = build_topology(mesh);
        p = std::make_unique<Prepared>();
        p->name = name;
        const Materials mat(Material{1e5, 0.3, 1000});
        p->model = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
        p->form = make_tet_edge_form<double>(mesh, topo, mat);
        p->u = deformation_displacement(mesh, Deformation::Twist);
        p->x.resize(p->u.size());
        for (std::size_t i = 0; i < p->x.size(); ++i) p->x[i] = std::sin(0.7 * double(i));
    }
    return *p;
}

// Compulsory traffic of one FE force call (each array streamed once per
// pass that touches it; random reads of u and zeta counted once):
// pass 1 reads edge, rest, L(E), u and writes p~, zeta, g; pass 2 reads the
// segments (first, E1, L(P)), zeta and updates g; pass 3 reads edge, p~, g
// and writes f (zeroed first).
double force_bytes(const EdgeModel<double>& m) {
    const double E = m.num_edges(), P = m.num_tseps(), V = m.num_vertices, s = sizeof(double);
    const double pass1 = E * (8 + 3 * s + s) + 3 * s * V + E * (3 * s + s + 8);
    const double pass2 = E * 4 + P * (4 + s) + E * s + 2 * E * 8;
    const double pass3 = E * (8 + 3 * s + 8) + 2 * 3 * s * V;
    return pass1 + pass2 + pass3;
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
                                                              PlanOptions{}, prepared(mesh).form);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (v == Variant::Colour && b == Backend::OpenMP && threads == 1)
            std::fprintf(stderr, "%s colourings (plan %.2f s): vertex segments %s; tsep g %s; tsep K %s\n", mesh.c_str(), s,
                         cur.k->vertex_colouring().stats().describe().c_str(),
                         cur.k->tsep_colouring().stats().describe().c_str(),
                         cur.k->stiffness_colouring().stats().describe().c_str());
        if (v == Variant::Owner && b == Backend::OpenMP && threads == 1) {
            const ForwardSpill &vs = cur.k->vertex_parts(), &es = cur.k->edge_parts();
            std::fprintf(stderr, "%s owner parts: %d; spill windows %.1f%% of the vertices, %.1f%% of the edges\n",
                         mesh.c_str(), int(vs.parts()), 100.0 * double(vs.spill_targets()) / std::max<index_t>(1, vs.items()),
                         100.0 * double(es.spill_targets()) / std::max<index_t>(1, es.items()));
        }
        cur.key = key;
    }
    return *cur.k;
}

void set_counters(benchmark::State& state, const Prepared& p, Kernel k) {
    state.counters["per_tet"] = benchmark::Counter(double(p.model.num_tets),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    if (k == Kernel::Force) {
        const double bytes = force_bytes(p.model);
        state.counters["bytes"] = bytes;
        state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
    }
}

void BM_Core(benchmark::State& state, std::string mesh, Kernel k) {
    const Prepared& p = prepared(mesh);
    std::vector<double> f(p.u.size()), y(p.u.size());
    EdgeState<double> st;
    EdgeStiffness<double> K;
    edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
    tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K);
    for (auto _ : state) {
        switch (k) {
            case Kernel::Force: edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st); break;
            case Kernel::Stiffness: tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K); break;
            case Kernel::Kx: edge_multiply(p.model, K, p.x.data(), y.data()); break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
    set_counters(state, p, k);
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
    set_counters(state, p, k);
}

// STREAM triad a = b + s c on arrays far larger than the caches, in the
// executor's fixed blocks; 24 bytes per element (no write-allocate counted,
// as STREAM does).
void BM_Triad(benchmark::State& state, int threads) {
    const std::size_t n = std::size_t(1) << 24;  // 3 x 128 MiB
    static std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
    const auto ex = make_executor(threads == 1 ? Backend::Serial : Backend::OpenMP, threads, Schedule::Static);
    const std::size_t chunk = (n + 63) / 64;
    const double s = 3.0;
    for (auto _ : state) {
        ex->for_chunks(64, [&](index_t k) {
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
    for (int t : {1, 2})
        benchmark::RegisterBenchmark(("triad/" + std::to_string(t)).c_str(), BM_Triad, t)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    for (const char* mesh : bench::kBenchMeshes) {
        for (Kernel k : {Kernel::Force, Kernel::Stiffness, Kernel::Kx})
            benchmark::RegisterBenchmark((std::string(name_of(k)) + "/serial/core/1/" + mesh).c_str(), BM_Core,
                                         std::string(mesh), k)
                ->Unit(benchmark::kMicrosecond)
                ->UseRealTime();
        for (Backend b : {Backend::OpenMP, Backend::TBB})
            for (Variant v : kAllVariants)
                for (int t : {1, 2})
                    for (Kernel k : {Kernel::Force, Kernel::Stiffness, Kernel::Kx}) {
                        const std::string name = std::string(name_of(k)) + "/" + to_string(b) + "/" + to_string(v) +
                                                 "/" + std::to_string(t) + "/" + mesh;
                        benchmark::RegisterBenchmark(name.c_str(), BM_Parallel, std::string(mesh), k, b, v, t)
                            ->Unit(benchmark::kMicrosecond)
                            ->UseRealTime();
                    }
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
