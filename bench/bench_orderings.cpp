// Memory orderings against each other: the edge force, stiffness and K x
// kernels (double, 1 thread) after renumbering the vertices with each
// ordering (edges, TSEPs and the tet-local form's batches follow). The
// force and stiffness are the FE operator's defaults: pair terms from the
// tet-local form (tet_form_forces, or tet_form_forces_ring when the form runs
// in tiles: the force alone keeps no state; tet_form_stiffness_all). Names:
// <kernel>/<ordering>/<mesh>.
// The partition issue's targets, on bunny-1m: best ordering >= 3x faster than
// the random shuffle and >= 1.3x faster than input order for the force kernel.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>

#include "bench_meshes.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "cpu/tet_edge_form.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

struct Prepared {
    EdgeModel<double> model;
    TetEdgeForm<double> form;
    std::vector<double> u, x;
    index_t tets;
};

const Prepared& prepared(const std::string& mesh_name, Ordering o) {
    static std::map<std::pair<std::string, Ordering>, std::unique_ptr<Prepared>> cache;
    auto& p = cache[{mesh_name, o}];
    if (!p) {
        const Mesh& base = bench::bench_mesh(mesh_name);
        const auto perm = vertex_ordering(base, o);
        const Mesh mesh = permute_mesh(base, perm);
        const Topology topo = build_topology(mesh);
        p = std::make_unique<Prepared>();
        const Materials mat(Material{1e5, 0.3, 1000});
        p->model = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
        p->model.target = {};  // the TSEP-list stiffness is not run
        p->form = make_tet_edge_form<double>(mesh, topo, mat);
        p->u = deformation_displacement(mesh, Deformation::Twist);
        p->x.resize(p->u.size());
        for (std::size_t i = 0; i < p->x.size(); ++i) p->x[i] = std::sin(0.7 * i);
        p->tets = mesh.num_tets();
    }
    return *p;
}

enum class Kernel { Force, Stiffness, Kx };

void BM_Ordered(benchmark::State& state, std::string mesh, Ordering o, Kernel k) {
    const Prepared& p = prepared(mesh, o);
    std::vector<double> f(p.u.size()), y(p.u.size());
    EdgeState<double> st;
    EdgeStiffness<double> K;
    tet_form_forces<ModelKind::FE, false>(p.model, p.form, p.u.data(), f.data(), st);
    tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K);
    // The force alone keeps no state (as ElasticOperator::keep_state(false)):
    // on the ring when the form runs in tiles.
    FormRing<double> ring = make_form_ring(p.form, p.model.edge_first);
    for (auto _ : state) {
        if (k == Kernel::Force && !ring.empty())
            tet_form_forces_ring<ModelKind::FE, false>(p.model, p.form, p.u.data(), f.data(), ring);
        else if (k == Kernel::Force)
            tet_form_forces<ModelKind::FE, false>(p.model, p.form, p.u.data(), f.data(), st);
        else if (k == Kernel::Stiffness)
            tet_form_stiffness_all<ModelKind::FE>(p.model, p.form, st, K);
        else
            edge_multiply(p.model, K, p.x.data(), y.data());
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
    state.counters["per_tet"] = benchmark::Counter(double(p.tets), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    for (const char* mesh : {"box-1200", "bunny-4k", "armadillo-7k", "bunny-250k", "bunny-1m"})
        for (auto [k, kname] : {std::pair{Kernel::Force, "force"}, {Kernel::Stiffness, "stiffness"}, {Kernel::Kx, "kx"}})
            for (Ordering o : all_orderings())
                benchmark::RegisterBenchmark((std::string(kname) + "/" + to_string(o) + "/" + mesh).c_str(), BM_Ordered,
                                             std::string(mesh), o, k)
                    ->Unit(benchmark::kMicrosecond);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
