// The paper's comparison (Kikuuwe et al. 2009, Table 1) reproduced: time of
// F, K, F+K and a whole semi-implicit step, edge-based FE and SN against the
// per-tet method, 1 thread and all threads, double and float, on the paper's
// mesh sizes (box-1200, spot-2k for the dinosaur, bunny-4k, armadillo-7k;
// generated boxes of the same size where ../shared/meshes is absent), plus
// the force kernel on bunny-1m (1 thread, double: the large-mesh
// target), in its input numbering and renumbered by RCM ("bunny-1m@rcm").
//
// Names: paper/<kernel>/<method>/<precision>/<threads>t/<mesh>, kernel in
// force | stiffness | force+stiffness | step; method edge-fe | edge-sn | tet.
// 1 thread runs the CPU back-end's serial loops (make_cpu_operator without an
// executor, the serial Simulator); more threads run its threaded variants (OpenMP executor, the
// default variant Auto: owner when the mesh's numbering has locality, else
// gather, both deterministic; the per-tet operator runs coloured) and the
// Simulator on the same executor. The paper's meshes run renumbered by RCM,
// the library's default ordering (`edgefem simulate`, `forces`, `bench`),
// for every method alike: in their input numbering the 2-thread rows ran
// the gather variant on the TSEP list, slower than 1 thread. bunny-1m runs
// in both numberings.
//
// Kernels run on the twist configuration (edgefem/core/deformations.hpp),
// Y = 1e5 Pa, nu = 0.3. The step: h = 1 ms, gravity -z, the lowest 1% of
// the mesh height fixed, 20 warm-started CG iterations (as bench_step).
//
// Counters: per_tet (s per tet, shown in ns), flops_per_tet (hand-derived
// formulas of bench/flop_counts.hpp, checked exactly against a counting
// scalar by tests/test_flop_counts.cpp and again at start-up here; the
// per-tet counts leave out the energy arithmetic the compiler drops),
// gflops (flops_per_tet / per_tet), tets, edges, tseps.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "bench_meshes.hpp"
#include "lab/benchmark_scene.hpp"
#include "counting_scalar.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/cpu_operator.hpp"
#include "flop_counts.hpp"

using namespace edgefem;

namespace {

enum class Kernel { Force, Stiffness, ForceStiffness, Step };
enum class Which { EdgeFE, EdgeSN, Tet };

const char* name_of(Kernel k) {
    switch (k) {
        case Kernel::Force: return "force";
        case Kernel::Stiffness: return "stiffness";
        case Kernel::ForceStiffness: return "force+stiffness";
        default: return "step";
    }
}
const char* name_of(Which m) { return m == Which::EdgeFE ? "edge-fe" : m == Which::EdgeSN ? "edge-sn" : "tet"; }
ModelKind model_of(Which m) { return m == Which::EdgeSN ? ModelKind::SN : ModelKind::FE; }
Method method_of(Which m) { return m == Which::Tet ? Method::Tet : Method::Edge; }

const Materials& materials() {
    static const Materials mat(Material{1e5, 0.3, 1000});
    return mat;
}

// Item counts of a mesh (from its edge model) and the instrumented check.
const flops::Items& items(const std::string& mesh_name) {
    static std::map<std::string, flops::Items> cache;
    auto it = cache.find(mesh_name);
    if (it != cache.end()) return it->second;
    const Mesh& mesh = bench::bench_mesh(mesh_name);
    const Topology topo = build_topology(mesh);
    const EdgeModel<double> em = make_edge_model<double>(topo, compute_coefficients(mesh, topo, materials()));
    const flops::Items n = flops::items_of(em);
    if (mesh.num_tets() <= 20000) {  // instrumented run: formulas must match exactly
        const TetModel<double> tm = make_tet_model<double>(mesh, materials());
        const TetEdgeForm<double> form = make_tet_edge_form<double>(mesh, topo, materials());
        const auto got = flops::count_kernels(em, tm, deformation_displacement(mesh, Deformation::Twist), &form);
        const bool ok = double(got.edge_force_fe) == flops::edge_force(n, ModelKind::FE).counted &&
                        double(got.edge_stiffness_fe) == flops::edge_stiffness(n, ModelKind::FE).counted &&
                        double(got.edge_stiffness_fe_tet_local) == flops::edge_stiffness_tet_local(n).counted &&
                        double(got.edge_force_fe_tet_local) == flops::edge_force_tet_local(n).counted &&
                        double(got.edge_force_sn) == flops::edge_force(n, ModelKind::SN).counted &&
                        double(got.tet_force) == flops::tet_force(n, true).counted &&
                        double(got.tet_stiffness) == flops::tet_stiffness(n).counted;
        std::fprintf(stderr, "%s: E=%.0f P=%.0f T=%.0f; FLOP formulas vs counting scalar: %s\n", mesh_name.c_str(), n.E,
                     n.P, n.T, ok ? "exact match" : "MISMATCH");
    }
    return cache.emplace(mesh_name, n).first->second;
}

// The edge FE stiffness and forces run the tet-local form (the operators'
// default layout); SN has only the edge terms.
flops::Count stiffness_flops(const flops::Items& n, ModelKind kind) {
    return kind == ModelKind::FE ? flops::edge_stiffness_tet_local(n) : flops::edge_stiffness(n, kind);
}
flops::Count force_flops(const flops::Items& n, ModelKind kind) {
    return kind == ModelKind::FE ? flops::edge_force_tet_local(n) : flops::edge_force(n, kind);
}

double flops_of(const flops::Items& n, Kernel k, Which m) {
    const ModelKind kind = model_of(m);
    if (m == Which::Tet) {
        switch (k) {
            case Kernel::Force: return flops::tet_force(n, false).total;
            case Kernel::Stiffness: return flops::tet_stiffness(n).total;
            case Kernel::ForceStiffness: return (flops::tet_force(n, false) + flops::tet_stiffness(n)).total;
            default: return 0;
        }
    }
    switch (k) {
        case Kernel::Force: return force_flops(n, kind).total;
        case Kernel::Stiffness: return stiffness_flops(n, kind).total;
        case Kernel::ForceStiffness: return (force_flops(n, kind) + stiffness_flops(n, kind)).total;
        default: return 0;
    }
}

std::shared_ptr<const Executor> executor_for(int threads) {
    static std::map<int, std::shared_ptr<const Executor>> cache;
    auto& e = cache[threads];
    if (!e) e = make_executor(Backend::OpenMP, threads, Schedule::Dynamic);
    return e;
}

template <class S>
std::unique_ptr<ElasticOperator<S>> make_op(const Mesh& mesh, Which m, int threads) {
    if (threads == 1) return make_cpu_operator<S>(mesh, materials(), model_of(m), method_of(m));
    return make_cpu_operator<S>(mesh, materials(), model_of(m), method_of(m), CpuOptions{executor_for(threads), Variant::Auto}, PlanOptions{});
}

Scene step_scene(const Mesh& mesh, Which m) {
    Scene s = step_benchmark_scene(mesh, materials());
    s.model = model_of(m);
    s.method = method_of(m);
    return s;
}

template <class S>
void BM_Paper(benchmark::State& state, std::string mesh_name, Kernel k, Which m, int threads) {
    const bool input_numbering = mesh_name == "bunny-1m";
    const Mesh& mesh = bench::bench_mesh(input_numbering || mesh_name.find('@') != std::string::npos
                                             ? mesh_name
                                             : mesh_name + "@rcm");
    const flops::Items& n = items(mesh_name);
    if (k == Kernel::Step) {
        Scene s = step_scene(mesh, m);
        std::unique_ptr<Simulator<S>> sim;
        if (threads == 1) {
            sim = std::make_unique<Simulator<S>>(std::move(s), nullptr, cpu_operator_factory<S>());
        } else {
            auto ex = executor_for(threads);
            sim = std::make_unique<Simulator<S>>(std::move(s), ex, cpu_operator_factory<S>({ex}));
        }
        for (int i = 0; i < 3; ++i) sim->step();  // warm: K, buffers, a moving state
        for (auto _ : state) sim->step();
        state.counters["cg_iterations"] = sim->last_stats().solver_iterations;
    } else {
        auto op = make_op<S>(mesh, m, threads);
        const auto ud = deformation_displacement(mesh, Deformation::Twist);
        std::vector<S> u(ud.begin(), ud.end()), f(u.size());
        op->forces(u.data(), f.data(), false);
        op->build_stiffness(false);
        op->keep_state(k != Kernel::Force);  // the force alone: no state for a K (the per-tet method keeps none)
        for (auto _ : state) {
            switch (k) {
                case Kernel::Force: op->forces(u.data(), f.data(), false); break;
                case Kernel::Stiffness: op->build_stiffness(false); break;
                default:
                    op->forces(u.data(), f.data(), false);
                    op->build_stiffness(false);
                    break;
            }
            benchmark::DoNotOptimize(f.data());
            benchmark::ClobberMemory();
        }
        const double fl = flops_of(n, k, m) / n.T;
        state.counters["flops_per_tet"] = fl;
        state.counters["gflops"] = benchmark::Counter(fl * n.T * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
    }
    state.counters["per_tet"] =
        benchmark::Counter(n.T, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.counters["tets"] = n.T;
    state.counters["edges"] = n.E;
    state.counters["tseps"] = n.P;
    state.counters["threads"] = threads;
}

void add(const std::string& mesh, Kernel k, Which m, bool single, int threads) {
    const std::string name = std::string("paper/") + name_of(k) + "/" + name_of(m) + "/" + (single ? "float" : "double") +
                             "/" + std::to_string(threads) + "t/" + mesh;
    auto* b = single ? benchmark::RegisterBenchmark(name.c_str(), BM_Paper<float>, mesh, k, m, threads)
                     : benchmark::RegisterBenchmark(name.c_str(), BM_Paper<double>, mesh, k, m, threads);
    b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    const int all = std::max(1, hardware_threads());
    std::vector<int> thread_counts = {1};
    if (all > 1) thread_counts.push_back(all);
    for (const char* mesh : {"box-1200", "spot-2k", "bunny-4k", "armadillo-7k"})
        for (Kernel k : {Kernel::Force, Kernel::Stiffness, Kernel::ForceStiffness, Kernel::Step})
            for (Which m : {Which::EdgeFE, Which::EdgeSN, Which::Tet})
                for (bool single : {false, true})
                    for (int t : thread_counts) add(mesh, k, m, single, t);
    // The large-mesh force target (about 0.5 GB of models): 1 thread, double.
    // In its input numbering and renumbered by RCM (the target's measure).
    for (const char* mesh : {"bunny-1m", "bunny-1m@rcm"})
        for (Which m : {Which::EdgeFE, Which::Tet}) add(mesh, Kernel::Force, m, false, 1);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
