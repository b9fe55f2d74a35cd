// Whole simulation steps, and what a scene's unused features cost.
// step/<variant>/<mesh>: one step, h = 1 ms, gravity -z, the lowest 1% of
// the mesh height fixed, 20 warm-started CG iterations (a haptic budget).
// Variants: semi (FE, no damping), semi+alpha, semi+beta, semi+energy (the
// energy computed each step on top), semi-sn, explicit (never builds K),
// semi-direct (assembled K, sparse LDLT instead of matrix-free CG).
// force/<variant>/<mesh> isolates compile-time specialisations: FE against
// FE with L(P) = 0 (TSEP loop still run) against SN (TSEP loop compiled
// away), and energy on/off.
#include <benchmark/benchmark.h>

#include <functional>

#include "bench_meshes.hpp"
#include "lab/benchmark_scene.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/cpu_backend.hpp"

using namespace edgefem;

namespace {

Scene step_scene(const Mesh& mesh) { return step_benchmark_scene(mesh, Material{1e5, 0.3, 1000}); }

void BM_Step(benchmark::State& state, std::string mesh_name, std::function<void(Scene&)> tweak, bool energy) {
    Scene s = step_scene(bench::bench_mesh(mesh_name));
    tweak(s);
    Simulator<double> sim(std::move(s), nullptr, cpu_operator_factory<double>());
    for (int k = 0; k < 3; ++k) sim.step();  // warm: K, buffers, a moving state
    for (auto _ : state) {
        sim.step();
        if (energy) benchmark::DoNotOptimize(sim.energies().total());
    }
    state.counters["cg_iterations"] = sim.last_stats().solver_iterations;
}

template <ModelKind Kind, bool Energy>
void BM_Force(benchmark::State& state, std::string mesh_name, bool zero_lp) {
    const Mesh& mesh = bench::bench_mesh(mesh_name);
    const Topology topo = build_topology(mesh);
    EdgeModel<double> m = make_edge_model<double>(topo, compute_coefficients(mesh, topo, Material{1e5, 0.3, 1000}));
    if (zero_lp) std::fill(m.LP.begin(), m.LP.end(), 0.0);
    const auto u = deformation_displacement(mesh, Deformation::Twist);
    std::vector<double> f(u.size());
    EdgeState<double> st;
    for (auto _ : state) {
        benchmark::DoNotOptimize(edge_forces<Kind, Energy>(m, u.data(), f.data(), st));
        benchmark::ClobberMemory();
    }
    state.counters["per_tet"] = benchmark::Counter(double(mesh.num_tets()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    const std::vector<std::pair<std::string, std::function<void(Scene&)>>> variants = {
        {"semi", [](Scene&) {}},
        {"semi+alpha", [](Scene& s) { s.rayleigh_alpha = 0.5; }},
        {"semi+beta", [](Scene& s) { s.rayleigh_beta = 1e-3; }},
        {"semi-sn", [](Scene& s) { s.model = ModelKind::SN; }},
        {"explicit", [](Scene& s) {
             s.integrator = Integrator::Explicit;
             s.dt = 1e-5;
             s.solver.cg_fixed_iterations = 0;  // a CG budget only for the semi-implicit step
         }},
        {"semi-direct", [](Scene& s) {
             s.solver.linear_solver = LinearSolver::Direct;
             s.solver.cg_fixed_iterations = 0;
         }},
        {"semi-cg-1e-6", [](Scene& s) {
             s.solver.cg_fixed_iterations = 0;
             s.solver.cg_tolerance = 1e-6;
         }},
    };
    for (const char* mesh : {"box-1200", "bunny-4k", "armadillo-7k", "bunny-50k"}) {
        for (const auto& [name, tweak] : variants)
            benchmark::RegisterBenchmark(("step/" + name + "/" + mesh).c_str(), BM_Step, std::string(mesh), tweak, false)
                ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark((std::string("step/semi+energy/") + mesh).c_str(), BM_Step, std::string(mesh),
                                     [](Scene&) {}, true)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark((std::string("force/fe/") + mesh).c_str(), BM_Force<ModelKind::FE, false>,
                                     std::string(mesh), false);
        benchmark::RegisterBenchmark((std::string("force/fe+energy/") + mesh).c_str(), BM_Force<ModelKind::FE, true>,
                                     std::string(mesh), false);
        benchmark::RegisterBenchmark((std::string("force/fe-lp0/") + mesh).c_str(), BM_Force<ModelKind::FE, false>,
                                     std::string(mesh), true);
        benchmark::RegisterBenchmark((std::string("force/sn/") + mesh).c_str(), BM_Force<ModelKind::SN, false>,
                                     std::string(mesh), false);
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
