// Partition-aware colouring (issue #5): the colour variant's force and K x
// kernels (edge FE, double) on metis-ordered meshes, with three
// choices of colouring unit for the edge scatter and the TSEP segments:
//   b1     one item per unit (plain global colouring),
//   b1024  blocks of 1024 consecutive items (blocked_colouring(), the default),
//   parts  the edges of one METIS part per unit (part_colouring(): each
//          thread owns whole parts; parts sized for L2 by the metis ordering).
// Names: <kernel>/<mesh>/serial (core's loop) or
// <kernel>/<mesh>/<omp|tbb>-t<threads>-<units> (OpenMP at 1 and 2 threads,
// TBB at 2). Counters: colours and units of the
// edge colouring, colours of the TSEP-strain colouring (seg_colours), time
// per tet, and (parts) the share of edges whose first vertex has a
// neighbour in another part (boundary_share).
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <tuple>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

enum class Units { B1, B1024, Parts };
const char* to_string(Units u) { return u == Units::B1 ? "b1" : u == Units::B1024 ? "b1024" : "parts"; }

// A metis-ordered mesh's model, parts, state and stiffness (loaded once).
struct Prepared {
    EdgeModel<double> model;
    std::vector<index_t> part_first;
    std::vector<double> u, x;
    EdgeStiffness<double> K;  // core's, for K x
    index_t tets = 0;
    // Share of edges whose first vertex has a neighbour in another part: what
    // an interior/boundary split would still colour (an edge, or TSEP
    // segment, whose V0 is interior to part p writes only p's vertices and
    // edges, so all interior items of all parts could run in one pass).
    double boundary_share = 0;
};

const Prepared& prepared(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Prepared>> cache;
    auto& p = cache[name];
    if (!p) {
        const Mesh& base = bench::bench_mesh(name);
        PartitionedOrdering po = vertex_ordering_with_parts(base, Ordering::MetisKway);  // = vertex_ordering(.., metis)
        const Mesh mesh = permute_mesh(base, po.new_of_old);
        const Topology topo = build_topology(mesh);
        p = std::make_unique<Prepared>();
        p->model = make_edge_model<double>(topo, compute_coefficients(mesh, topo, Material{1e5, 0.3, 1000}));
        p->part_first = std::move(po.part_first);
        p->u = deformation_displacement(mesh, Deformation::Twist);
        p->x.resize(p->u.size());
        for (std::size_t i = 0; i < p->x.size(); ++i) p->x[i] = std::sin(0.7 * double(i));
        std::vector<double> f(p->u.size());
        EdgeState<double> st;
        edge_forces<ModelKind::FE, false>(p->model, p->u.data(), f.data(), st);
        edge_stiffness_all<ModelKind::FE>(p->model, st, p->K);
        p->tets = mesh.num_tets();
        // Boundary vertices: those with a neighbour in another part.
        const auto& m = p->model;
        const std::vector<index_t> part = vertex_parts(p->part_first);
        std::vector<char> boundary_vertex(m.num_vertices, 0);
        for (const auto& e : m.edge)
            if (part[e[0]] != part[e[1]]) boundary_vertex[e[0]] = boundary_vertex[e[1]] = 1;
        index_t boundary = 0;
        for (const auto& e : m.edge) boundary += boundary_vertex[e[0]];
        p->boundary_share = m.num_edges() ? double(boundary) / m.num_edges() : 0.0;
    }
    return *p;
}

PlanOptions plan(const Prepared& p, Units units) {
    PlanOptions o;
    o.stiffness = false;  // force and K x only (K x takes core's K)
    if (units == Units::B1) {
        o.vertex_colouring = o.segment_colouring = ColouringOptions{};
    } else if (units == Units::Parts) {
        o.vertex_colouring = part_vertex_colouring(p.part_first, blocked_vertex_colouring());
        o.segment_colouring = part_colouring(p.model, p.part_first, blocked_colouring());
    }  // B1024: PlanOptions' defaults (segments: blocked_colouring(), vertices: blocked_vertex_colouring())
    return o;
}

// The kernels object of each (mesh, units, threads), built on first use and
// kept (bunny-1m: about 0.3 GB each), so that repetitions can be interleaved
// (--benchmark_enable_random_interleaving) without re-colouring.
const ParallelEdgeKernels<double>& kernels(const std::string& name, Units units, Backend backend, int threads) {
    static std::map<std::tuple<std::string, Units, Backend, int>, std::unique_ptr<ParallelEdgeKernels<double>>> cache;
    auto& slot = cache[{name, units, backend, threads}];
    if (!slot) {
        const Prepared& p = prepared(name);
        slot = std::make_unique<ParallelEdgeKernels<double>>(p.model, make_executor(backend, threads), Variant::Colour,
                                                             plan(p, units));
    }
    return *slot;
}

void BM(benchmark::State& state, std::string name, int kernel, Backend backend, int threads, Units units) {
    const Prepared& p = prepared(name);
    std::vector<double> f(p.u.size()), y(p.u.size());
    EdgeState<double> st;
    if (backend == Backend::Serial) {
        for (auto _ : state) {
            if (kernel == 0)
                edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
            else
                edge_multiply(p.model, p.K, p.x.data(), y.data());
            benchmark::ClobberMemory();
        }
    } else {
        const ParallelEdgeKernels<double>& k = kernels(name, units, backend, threads);
        k.forces<ModelKind::FE, false>(p.u.data(), f.data(), st);  // warm-up
        for (auto _ : state) {
            if (kernel == 0)
                k.forces<ModelKind::FE, false>(p.u.data(), f.data(), st);
            else
                k.multiply(p.K, p.x.data(), y.data());
            benchmark::ClobberMemory();
        }
        const Colouring& ce = k.vertex_colouring();
        state.counters["colours"] = ce.colours();
        state.counters["units"] = double(ce.num_units());
        state.counters["seg_colours"] = k.tsep_colouring().colours();
        if (units == Units::Parts) state.counters["boundary_share"] = p.boundary_share;
    }
    state.counters["per_tet"] = benchmark::Counter(double(p.tets), benchmark::Counter::kIsIterationInvariantRate |
                                                                       benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    const char* kernel_names[] = {"force", "kx"};
    for (std::string mesh : bench::kBenchMeshes) {
        for (int k = 0; k < 2; ++k)
            benchmark::RegisterBenchmark((std::string(kernel_names[k]) + "/" + mesh + "/serial").c_str(), BM, mesh, k,
                                         Backend::Serial, 0, Units::B1)
                ->UseRealTime();
        // OpenMP at 1 and 2 threads; TBB at 2 threads as a cross-check (its
        // arena degrades more gracefully than OpenMP's barriers when the
        // second core is taken by another process).
        const std::pair<Backend, int> runs[] = {{Backend::OpenMP, 1}, {Backend::OpenMP, 2}, {Backend::TBB, 2}};
        for (Units units : {Units::B1, Units::B1024, Units::Parts})
            for (auto [backend, t] : runs)
                for (int k = 0; k < 2; ++k)
                    benchmark::RegisterBenchmark((std::string(kernel_names[k]) + "/" + mesh + "/" + to_string(backend) + "-t" +
                                                  std::to_string(t) + "-" + to_string(units))
                                                     .c_str(),
                                                 BM, mesh, k, backend, t, units)
                        ->UseRealTime();
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
