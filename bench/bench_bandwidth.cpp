// Memory bandwidth against the kernels' data rate (docs/parallel.md,
// "Memory bandwidth"): the STREAM kernels (copy, scale, add, triad,
// read-only sum; 3 x 64 MiB) at 1 and 2 OpenMP threads, then the edge FE
// force and K x kernels (double, twist configuration) on RCM-ordered meshes,
// core's serial loops and the OpenMP gather and private variants at 1 and 2
// threads.
// Names: stream/<kernel>/<threads>, <kernel>/<impl>/<threads>/<mesh>, and
// loop/<edge-strain|tsep|scatter>/<mesh>: core's three force loops timed one
// at a time (1 thread), to see which one falls short of the bandwidth.
// Counters (rates over wall-clock time, UseRealTime):
//   bytes_per_second           STREAM-counted bytes (no write-allocate) or the
//                              kernel's compulsory bytes per call
//                              (force_bytes_per_call, kx_bytes_per_call)
//   bytes_per_second_per_pass  the kernel's per-pass count (TrafficModel::PerPass)
//   bytes                      the kernel's compulsory bytes per call
//   fraction_of_triad          kernel rate / the stream/triad rate at the same
//                              thread count measured earlier in this run (absent
//                              when the triad was filtered out)
// box-1200 (cache-resident; for the ctest smoke run) is included so
// --benchmark_filter=box-1200 selects something cheap.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "lab/stream_bandwidth.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

using clock_type = std::chrono::steady_clock;

// Triad GB/s per thread count, as measured by stream/triad/<threads> in this run.
std::map<int, double>& triad_rates() {
    static std::map<int, double> r;
    return r;
}

// ---- STREAM -----------------------------------------------------------------

enum class StreamKernel { Copy, Scale, Add, Triad, Sum };
const char* name_of(StreamKernel k) {
    switch (k) {
        case StreamKernel::Copy: return "copy";
        case StreamKernel::Scale: return "scale";
        case StreamKernel::Add: return "add";
        case StreamKernel::Triad: return "triad";
        default: return "sum";
    }
}
double bytes_per_element(StreamKernel k) {
    switch (k) {
        case StreamKernel::Copy: return kStreamCopyBytes;
        case StreamKernel::Scale: return kStreamScaleBytes;
        case StreamKernel::Add: return kStreamAddBytes;
        case StreamKernel::Triad: return kStreamTriadBytes;
        default: return kStreamSumBytes;
    }
}

struct StreamArrays {
    static constexpr std::size_t n = StreamOptions{}.elements;  // 64 MiB each
    std::vector<double> a, b, c;
    StreamArrays() : a(n, 1.0), b(n, 2.0), c(n, 0.0) {}
};

void BM_Stream(benchmark::State& state, StreamKernel k, int threads) {
    static StreamArrays arr;
    const auto ex = make_executor(Backend::OpenMP, threads);
    double sink = 0;
    const auto t0 = clock_type::now();
    for (auto _ : state) {
        switch (k) {
            case StreamKernel::Copy: stream_copy(*ex, arr.a, arr.c); break;
            case StreamKernel::Scale: stream_scale(*ex, arr.c, arr.b, 3.0); break;
            case StreamKernel::Add: stream_add(*ex, arr.a, arr.b, arr.c); break;
            case StreamKernel::Triad: stream_triad(*ex, arr.b, arr.c, arr.a, 3.0); break;
            case StreamKernel::Sum: sink += stream_sum(*ex, arr.a); break;
        }
        benchmark::DoNotOptimize(sink);
        benchmark::ClobberMemory();
    }
    const double seconds = std::chrono::duration<double>(clock_type::now() - t0).count();
    const double bytes = bytes_per_element(k) * double(StreamArrays::n);
    if (k == StreamKernel::Triad && state.iterations() > 0)
        triad_rates()[threads] = bytes * double(state.iterations()) / seconds;
    state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
}

// ---- Kernels ------------------------------------------------------------------

enum class Kernel { Force, Kx };

struct Prepared {
    std::string name;
    EdgeModel<double> model;
    std::vector<double> u, x;
};

// One mesh at a time (bunny-1m's model is ~0.4 GB), RCM-ordered as in
// bench_orderings.cpp.
const Prepared& prepared(const std::string& name) {
    static std::unique_ptr<Prepared> p;
    if (!p || p->name != name) {
        p.reset();
        const Mesh& base = bench::bench_mesh(name);
        const Mesh mesh = permute_mesh(base, vertex_ordering(base, Ordering::RCM));
        const Topology topo = build_topology(mesh);
        p = std::make_unique<Prepared>();
        p->name = name;
        p->model = make_edge_model<double>(topo, compute_coefficients(mesh, topo, Material{1e5, 0.3, 1000}));
        p->u = deformation_displacement(mesh, Deformation::Twist);
        p->x.resize(p->u.size());
        for (std::size_t i = 0; i < p->x.size(); ++i) p->x[i] = std::sin(0.7 * double(i));
    }
    return *p;
}

// The parallel kernels of the current (mesh, variant, threads), kept while
// consecutive benchmarks use them (TSEP-list stiffness: K x needs only the
// per-edge blocks).
ParallelEdgeKernels<double>& kernels(const std::string& mesh, Variant v, int threads) {
    static std::string key;
    static std::unique_ptr<ParallelEdgeKernels<double>> k;
    const std::string want = mesh + "/" + to_string(v) + "/" + std::to_string(threads);
    if (key != want) {
        k.reset();
        PlanOptions plan;
        plan.stiffness_layout = StiffnessLayout::TsepList;
        k = std::make_unique<ParallelEdgeKernels<double>>(prepared(mesh).model, make_executor(Backend::OpenMP, threads),
                                                          v, plan);
        key = want;
    }
    return *k;
}

// impl: "core" (serial loops) or a variant name.
void BM_Kernel(benchmark::State& state, std::string mesh, Kernel k, std::string impl, int threads) {
    const Prepared& p = prepared(mesh);
    ParallelEdgeKernels<double>* kern = impl == "core" ? nullptr : &kernels(mesh, parse_variant(impl), threads);
    std::vector<double> f(p.u.size()), y(p.u.size());
    EdgeState<double> st;
    EdgeStiffness<double> K;
    if (kern) {
        kern->resize(K);
        kern->forces<ModelKind::FE, false>(p.u.data(), f.data(), st);
        kern->stiffness<ModelKind::FE>(st, K);
    } else {
        edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
        edge_stiffness_all<ModelKind::FE>(p.model, st, K);
    }
    const auto t0 = clock_type::now();
    for (auto _ : state) {
        if (k == Kernel::Force) {
            if (kern)
                kern->forces<ModelKind::FE, false>(p.u.data(), f.data(), st);
            else
                edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
        } else {
            if (kern)
                kern->multiply(K, p.x.data(), y.data());
            else
                edge_multiply(p.model, K, p.x.data(), y.data());
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
    const double seconds = std::chrono::duration<double>(clock_type::now() - t0).count();
    const double bytes = k == Kernel::Force ? force_bytes_per_call(p.model) : kx_bytes_per_call(p.model);
    const double per_pass = k == Kernel::Force ? force_bytes_per_call(p.model, ModelKind::FE, TrafficModel::PerPass)
                                               : kx_bytes_per_call(p.model, TrafficModel::PerPass);
    state.counters["bytes"] = bytes;
    state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["bytes_per_second_per_pass"] =
        benchmark::Counter(per_pass, benchmark::Counter::kIsIterationInvariantRate);
    const auto triad = triad_rates().find(threads);
    if (triad != triad_rates().end() && state.iterations() > 0 && seconds > 0)
        state.counters["fraction_of_triad"] = bytes * double(state.iterations()) / seconds / triad->second;
}

// Core's three force loops, one at a time (the state is left by a full
// call first). Bytes: each loop's arrays once (PerPass split by loop).
enum class Loop { EdgeStrain, Tsep, Scatter };

void BM_ForceLoop(benchmark::State& state, std::string mesh, Loop loop) {
    const Prepared& p = prepared(mesh);
    const EdgeModel<double>& m = p.model;
    std::vector<double> f(p.u.size());
    EdgeState<double> st;
    edge_forces<ModelKind::FE, false>(m, p.u.data(), f.data(), st);
    const index_t ne = m.num_edges(), nv = m.num_vertices;
    for (auto _ : state) {
        switch (loop) {
            case Loop::EdgeStrain:
                for (index_t e = 0; e < ne; ++e)
                    kernel::edge_strain(m, p.u.data(), e, st.p.data(), st.zeta.data(), st.g.data());
                break;
            case Loop::Tsep:
                for (index_t e = 0; e < ne; ++e) kernel::tsep_strain_segment(m, e, st.zeta.data(), st.g.data());
                break;
            case Loop::Scatter:
                std::fill(f.begin(), f.end(), 0.0);
                for (index_t a = 0; a < nv; ++a) kernel::edge_force_segment(m, a, st.p.data(), st.g.data(), f.data());
                break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(st.g.data());
        benchmark::ClobberMemory();
    }
    const auto size = [](const auto& v) { return double(v.size() * sizeof(v[0])); };
    const double vec = size(p.u);
    double bytes = 0;
    switch (loop) {
        case Loop::EdgeStrain:  // edge, rest, L(E), u read; p~, zeta, g written
            bytes = size(m.edge) + size(m.rest) + size(m.LE) + vec + size(st.p) + size(st.zeta) + size(st.g);
            break;
        case Loop::Tsep:  // segments, E1, L(P), zeta read; g read and written
            bytes = size(m.tsep_first) + size(m.tsep_other) + size(m.LP) + size(st.zeta) + 2 * size(st.g);
            break;
        case Loop::Scatter:  // edge_first, edge, p~, g read; f zeroed, read, written
            bytes = size(m.edge_first) + size(m.edge) + size(st.p) + size(st.g) + 3 * vec;
            break;
    }
    state.counters["bytes"] = bytes;
    state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    for (int t : {1, 2})
        for (StreamKernel k :
             {StreamKernel::Copy, StreamKernel::Scale, StreamKernel::Add, StreamKernel::Triad, StreamKernel::Sum})
            benchmark::RegisterBenchmark(("stream/" + std::string(name_of(k)) + "/" + std::to_string(t)).c_str(),
                                         BM_Stream, k, t)
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
    // Kernel innermost, so each (mesh, variant, threads) plan is built once.
    const std::pair<const char*, int> impls[] = {{"core", 1}, {"gather", 1}, {"gather", 2}, {"private", 1}, {"private", 2}};
    for (const char* mesh : {"box-1200", "bunny-250k", "bunny-1m"})
        for (const auto& [impl, t] : impls)
            for (const auto& [k, kname] : {std::pair{Kernel::Force, "force"}, {Kernel::Kx, "kx"}})
                benchmark::RegisterBenchmark(
                    (std::string(kname) + "/" + impl + "/" + std::to_string(t) + "/" + mesh).c_str(), BM_Kernel,
                    std::string(mesh), k, std::string(impl), t)
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
    for (const char* mesh : {"box-1200", "bunny-250k", "bunny-1m"})
        for (const auto& [loop, lname] :
             {std::pair{Loop::EdgeStrain, "edge-strain"}, {Loop::Tsep, "tsep"}, {Loop::Scatter, "scatter"}})
            benchmark::RegisterBenchmark((std::string("loop/") + lname + "/" + mesh).c_str(), BM_ForceLoop,
                                         std::string(mesh), loop)
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
