// How many consecutive items the colour variant colours as one unit: force,
// stiffness and K x (edge FE, double) on RCM-ordered meshes, serial core
// loops against the TBB colour variant at 1 and 2 threads for block sizes
// 1..4096. Names: <kernel>/<mesh>/serial or colour-t<threads>-b<block>.
#include <benchmark/benchmark.h>

#include <map>

#include "bench_meshes.hpp"
#include "lab/deformations.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/cpu_operator.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

const Mesh& rcm_mesh(const std::string& name) {
    static std::map<std::string, Mesh> cache;
    auto it = cache.find(name);
    if (it == cache.end()) {
        const Mesh& m = bench::bench_mesh(name);
        it = cache.emplace(name, permute_mesh(m, vertex_ordering(m, Ordering::RCM))).first;
    }
    return it->second;
}

void BM(benchmark::State& state, std::string name, int threads, index_t block, int kernel) {
    const Mesh& mesh = rcm_mesh(name);
    const Material mat{1e5, 0.3, 1000};
    std::unique_ptr<ElasticOperator<double>> op;
    if (threads == 0) {
        op = make_cpu_operator<double>(mesh, mat, ModelKind::FE, Method::Edge);
    } else {
        PlanOptions o;
        // Vertex segments hold ~6 edges each: 1/6 of the block in vertices.
        o.segment_colouring.block = block;
        o.segment_colouring.max_chunk_items = std::max<index_t>(1024, 4 * block);
        o.vertex_colouring.block = std::max<index_t>(1, block / 6);
        o.vertex_colouring.max_chunk_items = std::max<index_t>(170, (4 * block) / 6);
        op = make_cpu_operator<double>(mesh, mat, ModelKind::FE, Method::Edge, CpuOptions{make_executor(Backend::TBB, threads), Variant::Colour}, o);
    }
    const auto u = deformation_displacement(mesh, Deformation::Twist);
    std::vector<double> f(u.size()), y(u.size());
    op->forces(u.data(), f.data(), false);
    op->build_stiffness(false);
    for (auto _ : state) {
        if (kernel == 0)
            op->forces(u.data(), f.data(), false);
        else if (kernel == 1)
            op->build_stiffness(false);
        else
            op->multiply(u.data(), y.data());
        benchmark::ClobberMemory();
    }
    state.counters["per_tet"] = benchmark::Counter(double(mesh.num_tets()),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    const char* kernels[] = {"force", "stiffness", "kx"};
    for (std::string mesh : {"box-1200", "bunny-4k", "bunny-250k"})
        for (int k = 0; k < 3; ++k) {
            benchmark::RegisterBenchmark((std::string(kernels[k]) + "/" + mesh + "/serial").c_str(), BM, mesh, 0, 1, k);
            for (int t : {1, 2})
                for (index_t b : {1, 64, 256, 1024, 4096})
                    benchmark::RegisterBenchmark(
                        (std::string(kernels[k]) + "/" + mesh + "/colour-t" + std::to_string(t) + "-b" + std::to_string(b)).c_str(),
                        BM, mesh, t, b, k);
        }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
