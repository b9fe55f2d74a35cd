// Memory layouts against each other (docs/layouts.md, "Tried and lost";
// measured: docs/lab/layouts-log.md, "Layouts"), double
// FE, one thread, twist configuration:
//   force/<layout>/<ordering>/<mesh>      the force kernel in each storage
//       layout of layout_kernels.hpp (<aos|soa>-<double|float>-<split|packed>),
//       and edge-model: core's edge_forces on EdgeModel<double> (the
//       production kernel, same layout as aos-double-split);
//   stiffness/<tsep-list|tet-local>/<ordering>/<mesh>   the edge FE
//       stiffness from the mesh-wide TSEP list (edge_stiffness_all) or the
//       per-tet 6x6 form (tet_form_stiffness_all), from one force call's state.
// Orderings: input (the file's) and rcm (the best in docs/layouts.md).
// Counters: per_tet (time per tet: ns on the console, seconds in JSON), and
// bytes_per_tet of precomputed data the model in that layout holds (force layouts: everything the force kernel reads;
// stiffness layouts: the whole model for forces and K).
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "lab/layout_kernels.hpp"
#include "cpu/tet_edge_form.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

const Materials kMaterial(Material{1e5, 0.3, 1000});

struct Prepared {
    Mesh mesh;
    EdgeModel<double> model;  // with stiffness targets
    TetEdgeForm<double> form;
    std::vector<double> u;
};

// The orderings of one mesh at a time (bunny-1m's models take ~1 GB per
// ordering), so that --benchmark_enable_random_interleaving within one mesh
// does not rebuild them.
const Prepared& prepared(const std::string& mesh_name, Ordering o) {
    static std::string current;
    static std::map<Ordering, std::unique_ptr<Prepared>> cache;
    if (current != mesh_name) {
        cache.clear();
        current = mesh_name;
    }
    auto& p = cache[o];
    if (!p) {
        const Mesh& base = bench::bench_mesh(mesh_name);
        p = std::make_unique<Prepared>();
        p->mesh = permute_mesh(base, vertex_ordering(base, o));
        const Topology topo = build_topology(p->mesh);
        p->model = make_edge_model<double>(topo, compute_coefficients(p->mesh, topo, kMaterial));
        p->form = make_tet_edge_form<double>(p->mesh, topo, kMaterial);
        p->u = deformation_displacement(p->mesh, Deformation::Twist);
    }
    return *p;
}

void set_counters(benchmark::State& state, const Prepared& p, double bytes_per_tet) {
    // CPU time per iteration and tet (shown in ns; seconds in JSON/CSV).
    state.counters["per_tet"] = benchmark::Counter(double(p.mesh.num_tets()),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.counters["bytes_per_tet"] = bytes_per_tet;
}

template <class L>
void BM_ForceLayout(benchmark::State& state, std::string mesh, Ordering o) {
    const Prepared& p = prepared(mesh, o);
    using S = typename L::scalar;
    const typename L::Model m = make_layout_model<L::vec, S, L::tsep>(p.model);
    const typename L::Vectors u = to_vec3_array<L::vec, S>(p.u.data(), m.num_vertices);
    typename L::Vectors f;
    typename L::State st;
    layout_forces(m, u, f, st);
    for (auto _ : state) {
        layout_forces(m, u, f, st);
        benchmark::DoNotOptimize(f.data.data());
        benchmark::ClobberMemory();
    }
    set_counters(state, p, m.bytes_per_tet());
}

void BM_ForceEdgeModel(benchmark::State& state, std::string mesh, Ordering o) {
    const Prepared& p = prepared(mesh, o);
    std::vector<double> f(p.u.size());
    EdgeState<double> st;
    edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
    for (auto _ : state) {
        edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
        benchmark::DoNotOptimize(f.data());
        benchmark::ClobberMemory();
    }
    set_counters(state, p, p.model.bytes_per_tet(false));
}

void BM_Stiffness(benchmark::State& state, std::string mesh, Ordering o, StiffnessLayout layout) {
    const Prepared& p = prepared(mesh, o);
    std::vector<double> f(p.u.size());
    EdgeState<double> st;
    EdgeStiffness<double> K;
    edge_forces<ModelKind::FE, false>(p.model, p.u.data(), f.data(), st);
    const bool tet_local = layout == StiffnessLayout::TetLocal;
    for (auto _ : state) {
        if (tet_local)
            tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K);
        else
            edge_stiffness_all<ModelKind::FE>(p.model, st, K);
        benchmark::DoNotOptimize(K.K.data());
        benchmark::ClobberMemory();
    }
    // The model each operator holds (elastic_operator.cpp): tet-local drops
    // the TSEP targets and adds the form.
    set_counters(state, p, tet_local ? p.model.bytes_per_tet(false) + p.form.bytes_per_tet() : p.model.bytes_per_tet(true));
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    for (const char* mesh : bench::kBenchMeshes)
        for (Ordering o : {Ordering::Input, Ordering::RCM}) {
            const std::string suffix = std::string("/") + to_string(o) + "/" + mesh;
            benchmark::RegisterBenchmark(("force/edge-model" + suffix).c_str(), BM_ForceEdgeModel, std::string(mesh), o)
                ->Unit(benchmark::kMicrosecond);
            for_each_force_layout([&]<class L>(L) {
                benchmark::RegisterBenchmark(("force/" + L::name() + suffix).c_str(), BM_ForceLayout<L>, std::string(mesh), o)
                    ->Unit(benchmark::kMicrosecond);
            });
            for (StiffnessLayout l : {StiffnessLayout::TsepList, StiffnessLayout::TetLocal})
                benchmark::RegisterBenchmark((std::string("stiffness/") + to_string(l) + suffix).c_str(), BM_Stiffness,
                                             std::string(mesh), o, l)
                    ->Unit(benchmark::kMicrosecond);
        }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
