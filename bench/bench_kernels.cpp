// Kernel timings: edge-based FE and SN against the per-tet method, for
// force, stiffness, force+stiffness and K x, in double and float, on the
// twist configuration. Names: <kernel>/<method>/<precision>/<mesh>; the
// per_tet counter is seconds per tet (shown as ns).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "bench_meshes.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "cpu/tet_edge_form.hpp"
#include "cpu/tet_kernels.hpp"

using namespace edgefem;

namespace {

enum class Kernel { Force, Stiffness, ForceStiffness, Kx };
enum class Method { EdgeFE, EdgeFE3Pass, EdgeFETetForm, EdgeSN, Tet };

const char* name_of(Kernel k) {
    switch (k) {
        case Kernel::Force: return "force";
        case Kernel::Stiffness: return "stiffness";
        case Kernel::ForceStiffness: return "force+stiffness";
        default: return "kx";
    }
}
const char* name_of(Method m) {
    switch (m) {
        case Method::EdgeFE: return "edge-fe";
        case Method::EdgeFE3Pass: return "edge-fe-3pass";
        case Method::EdgeFETetForm: return "edge-fe-tetform";
        case Method::EdgeSN: return "edge-sn";
        default: return "tet";
    }
}

template <class S>
struct Prepared {
    EdgeModel<S> edge;
    TetEdgeForm<S> form;
    BatchedTetModel<S> tet;
    std::vector<S> u, x;
};

template <class S>
const Prepared<S>& prepared(const std::string& name) {
    static std::map<std::string, std::unique_ptr<Prepared<S>>> cache;
    auto& p = cache[name];
    if (!p) {
        const Mesh& mesh = bench::bench_mesh(name);
        const Materials mat(Material{1e5, 0.3, 1000});
        const Topology topo = build_topology(mesh);
        p = std::make_unique<Prepared<S>>();
        p->edge = make_edge_model<S>(topo, compute_coefficients(mesh, topo, mat));
        p->form = make_tet_edge_form<S>(mesh, topo, mat);
        p->tet = make_batched_tet_model<S>(mesh, mat);
        const auto u = deformation_displacement(mesh, Deformation::Twist);
        p->u.assign(u.begin(), u.end());
        p->x.resize(u.size());
        for (std::size_t i = 0; i < u.size(); ++i) p->x[i] = S(std::sin(0.7 * i));
    }
    return *p;
}

template <ModelKind Kind, class S>
void run_edge(benchmark::State& state, const Prepared<S>& p, Kernel k) {
    std::vector<S> f(p.u.size()), y(p.u.size());
    EdgeState<S> st;
    EdgeStiffness<S> K;
    edge_forces<Kind, false>(p.edge, p.u.data(), f.data(), st);
    edge_stiffness_all<Kind>(p.edge, st, K);
    for (auto _ : state) {
        switch (k) {
            case Kernel::Force: edge_forces<Kind, false>(p.edge, p.u.data(), f.data(), st); break;
            case Kernel::Stiffness: edge_stiffness_all<Kind>(p.edge, st, K); break;
            case Kernel::ForceStiffness:
                edge_forces<Kind, false>(p.edge, p.u.data(), f.data(), st);
                edge_stiffness_all<Kind>(p.edge, st, K);
                break;
            case Kernel::Kx: edge_multiply(p.edge, K, p.x.data(), y.data()); break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
}

// The unfused FE force of before the TSEP loop and the scatter were fused
// (edge loop, TSEP loop, scatter loop over core's workers): the baseline the
// fused edge_forces is measured against in the same run. Force only.
template <class S>
void run_edge_3pass(benchmark::State& state, const Prepared<S>& p) {
    const EdgeModel<S>& m = p.edge;
    std::vector<S> f(p.u.size());
    EdgeState<S> st;
    const index_t ne = m.num_edges();
    st.resize(ne);
    for (auto _ : state) {
        for (index_t e = 0; e < ne; ++e) kernel::edge_strain(m, p.u.data(), e, st.p.data(), st.zeta.data(), st.g.data());
        for (index_t e = 0; e < ne; ++e) kernel::tsep_strain_segment(m, e, st.zeta.data(), st.g.data());
        std::fill(f.begin(), f.end(), S(0));
        for (index_t a = 0; a < m.num_vertices; ++a) kernel::edge_force_segment(m, a, st.p.data(), st.g.data(), f.data());
        benchmark::DoNotOptimize(f.data());
        benchmark::ClobberMemory();
    }
}

// The edge-based FE model with the tet-local form instead of the TSEP list.
template <class S>
void run_tet_form(benchmark::State& state, const Prepared<S>& p, Kernel k) {
    std::vector<S> f(p.u.size()), y(p.u.size());
    EdgeState<S> st;
    EdgeStiffness<S> K;
    tet_form_forces<ModelKind::FE, false>(p.edge, p.form, p.u.data(), f.data(), st);
    tet_form_stiffness_all<ModelKind::FE>(p.edge, p.form, st, K);
    for (auto _ : state) {
        switch (k) {
            case Kernel::Force: tet_form_forces<ModelKind::FE, false>(p.edge, p.form, p.u.data(), f.data(), st); break;
            case Kernel::Stiffness: tet_form_stiffness_all<ModelKind::FE>(p.edge, p.form, st, K); break;
            case Kernel::ForceStiffness:
                tet_form_forces<ModelKind::FE, false>(p.edge, p.form, p.u.data(), f.data(), st);
                tet_form_stiffness_all<ModelKind::FE>(p.edge, p.form, st, K);
                break;
            case Kernel::Kx: edge_multiply(p.edge, K, p.x.data(), y.data()); break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
}

template <class S>
void run_tet(benchmark::State& state, const Prepared<S>& p, Kernel k) {
    std::vector<S> f(p.u.size()), y(p.u.size());
    TetStiffness<S> K;
    tet_forces_stiffness<false>(p.tet, p.u.data(), f.data(), K);
    for (auto _ : state) {
        switch (k) {
            case Kernel::Force: tet_forces<false>(p.tet, p.u.data(), f.data()); break;
            case Kernel::Stiffness: tet_stiffness_all(p.tet, p.u.data(), K); break;
            case Kernel::ForceStiffness: tet_forces_stiffness<false>(p.tet, p.u.data(), f.data(), K); break;
            case Kernel::Kx: tet_multiply(p.tet, K, p.x.data(), y.data()); break;
        }
        benchmark::DoNotOptimize(f.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
}

template <class S>
void BM_Kernel(benchmark::State& state, std::string mesh, Method m, Kernel k) {
    const Prepared<S>& p = prepared<S>(mesh);
    if (m == Method::EdgeFE)
        run_edge<ModelKind::FE>(state, p, k);
    else if (m == Method::EdgeFE3Pass)
        run_edge_3pass(state, p);
    else if (m == Method::EdgeFETetForm)
        run_tet_form(state, p, k);
    else if (m == Method::EdgeSN)
        run_edge<ModelKind::SN>(state, p, k);
    else
        run_tet(state, p, k);
    state.counters["per_tet"] = benchmark::Counter(double(p.tet.num_tets()),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    for (const char* mesh : bench::kBenchMeshes)
        for (Kernel k : {Kernel::Force, Kernel::Stiffness, Kernel::ForceStiffness, Kernel::Kx})
            for (Method m : {Method::EdgeFE, Method::EdgeFE3Pass, Method::EdgeFETetForm, Method::EdgeSN, Method::Tet})
                for (int precision = 0; precision < 2; ++precision) {
                    if (m == Method::EdgeFE3Pass && k != Kernel::Force) continue;
                    const std::string name = std::string(name_of(k)) + "/" + name_of(m) + "/" +
                                             (precision ? "float" : "double") + "/" + mesh;
                    auto* b = precision ? benchmark::RegisterBenchmark(name.c_str(), BM_Kernel<float>, mesh, m, k)
                                        : benchmark::RegisterBenchmark(name.c_str(), BM_Kernel<double>, mesh, m, k);
                    b->Unit(benchmark::kMicrosecond);
                }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
