// Set-up cost: mesh validation, topology (edges, TSEPs, targets, adjacencies), coefficients
// and the kernel model, per mesh. The target: bunny-1m topology in a
// few seconds on one core.
#include <benchmark/benchmark.h>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/core/validate_mesh.hpp"

using namespace edgefem;

static void BM_Topology(benchmark::State& state, std::string name) {
    const Mesh& mesh = bench::bench_mesh(name);
    for (auto _ : state) {
        Topology topo = build_topology(mesh);
        benchmark::DoNotOptimize(topo.tseps.data());
    }
    state.counters["tets"] = mesh.num_tets();
    state.counters["per_tet"] = benchmark::Counter(double(mesh.num_tets()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

static void BM_Validate(benchmark::State& state, std::string name) {
    Mesh mesh = bench::bench_mesh(name);  // validate_mesh may reorient or compact (options off here)
    for (auto _ : state) {
        ValidationReport r = validate_mesh(mesh);
        benchmark::DoNotOptimize(r);
    }
    state.counters["per_tet"] = benchmark::Counter(double(mesh.num_tets()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

static void BM_Coefficients(benchmark::State& state, std::string name) {
    const Mesh& mesh = bench::bench_mesh(name);
    const Topology topo = build_topology(mesh);
    const Materials mat(Material{1e5, 0.3, 1000});
    for (auto _ : state) {
        Coefficients c = compute_coefficients(mesh, topo, mat);
        benchmark::DoNotOptimize(c.LP.data());
    }
    state.counters["per_tet"] = benchmark::Counter(double(mesh.num_tets()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    for (const char* name : bench::kBenchMeshes) {
        benchmark::RegisterBenchmark((std::string("topology/") + name).c_str(), BM_Topology, std::string(name))
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark((std::string("validate/") + name).c_str(), BM_Validate, std::string(name))
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark((std::string("coefficients/") + name).c_str(), BM_Coefficients, std::string(name))
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
