// The edge-based FE and SN models on the device, as gathers (no
// floating-point atomics, the same bits on every run): an edge pass (p~,
// zeta), a g pass that pulls each edge's TSEP terms, and vertex passes that
// pull from the incident edges (forces, K x, diagonal blocks); the
// stiffness pass pulls into each edge's block the TSEP blocks that target
// it. Every term is a formula of edgefem/physics/.
#include <algorithm>
#include <string>

#include "cuda/device_operators.cuh"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/operator_blocks.hpp"
#include "edgefem/physics/edge_blocks.hpp"
#include "edgefem/physics/edge_force.hpp"
#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/edge_stiffness.hpp"
#include "edgefem/physics/edge_strain.hpp"
#include "edgefem/physics/tsep_stiffness.hpp"

namespace edgefem::cuda {

// (A named namespace: nvcc's extended lambdas may not sit in an unnamed one.)
namespace edge_detail {

// Compressed rows from (row, entry) pairs, rows in [0, rows), entries of a
// row in the order given.
template <class Rows>
void build_lists(index_t rows, std::size_t count, Rows&& row_of, std::vector<index_t>& first,
                 std::vector<index_t>& entry, const std::vector<index_t>& value) {
    first.assign(std::size_t(rows) + 1, 0);
    for (std::size_t k = 0; k < count; ++k) ++first[std::size_t(row_of(k)) + 1];
    for (index_t r = 0; r < rows; ++r) first[r + 1] += first[r];
    std::vector<index_t> next(first.begin(), first.end() - 1);
    entry.assign(count, 0);
    for (std::size_t k = 0; k < count; ++k) entry[std::size_t(next[row_of(k)]++)] = value[k];
}

// The device copy of an EdgeModel plus the gather lists.
template <class S>
struct DeviceEdgeModel {
    index_t nv = 0, ne = 0, np = 0;
    std::vector<std::array<index_t, 2>> edge_host;  // for_each_block
    DeviceArray<index_t> edge;                      // 2 #E
    DeviceArray<S> rest, LE, LP;                    // 3 #E, #E, #P
    DeviceArray<index_t> pair_e0, pair_e1, target;  // #P, #P, 4 #P
    // g gather: per edge, its TSEPs as 2 P + (1 if the edge is E1).
    DeviceArray<index_t> g_first, g_entry;
    // vertex gathers: per vertex, its edges as 2 e + (1 if the vertex is V1).
    DeviceArray<index_t> v_first, v_entry;
    // stiffness gather: per edge, the TSEP slots 4 P + k that target it.
    DeviceArray<index_t> k_first, k_entry;

    DeviceEdgeModel(const EdgeModel<S>& m, bool fe) {
        nv = m.num_vertices;
        ne = m.num_edges();
        np = fe ? m.num_tseps() : 0;
        edge_host = m.edge;
        std::vector<index_t> e2(2 * std::size_t(ne));
        for (index_t e = 0; e < ne; ++e) {
            e2[2 * e] = m.edge[e][0];
            e2[2 * e + 1] = m.edge[e][1];
        }
        edge = DeviceArray<index_t>(e2);
        rest = DeviceArray<S>(m.rest);
        LE = DeviceArray<S>(m.LE);
        std::vector<index_t> first, entry;
        {  // vertex -> incident edges
            std::vector<index_t> value(2 * std::size_t(ne));
            for (std::size_t k = 0; k < value.size(); ++k) value[k] = index_t(k);  // 2 e + side
            build_lists(nv, value.size(), [&](std::size_t k) { return e2[k]; }, first, entry, value);
            v_first = DeviceArray<index_t>(first);
            v_entry = DeviceArray<index_t>(entry);
        }
        if (np == 0) return;
        LP = DeviceArray<S>(m.LP);
        std::vector<index_t> e0(np), tgt(4 * std::size_t(np));
        for (index_t a = 0; a < ne; ++a)
            for (index_t P = m.tsep_first[a]; P < m.tsep_first[a + 1]; ++P) e0[P] = a;
        for (index_t P = 0; P < np; ++P)
            for (int k = 0; k < 4; ++k) tgt[4 * std::size_t(P) + k] = m.target[P][k];
        pair_e0 = DeviceArray<index_t>(e0);
        pair_e1 = DeviceArray<index_t>(m.tsep_other);
        target = DeviceArray<index_t>(tgt);
        {  // edge -> its TSEPs (as E0, then as E1)
            std::vector<index_t> value(2 * std::size_t(np)), row(2 * std::size_t(np));
            for (index_t P = 0; P < np; ++P) {
                value[2 * P] = 2 * P;
                row[2 * P] = e0[P];
                value[2 * P + 1] = 2 * P + 1;
                row[2 * P + 1] = m.tsep_other[P];
            }
            build_lists(ne, value.size(), [&](std::size_t k) { return row[k]; }, first, entry, value);
            g_first = DeviceArray<index_t>(first);
            g_entry = DeviceArray<index_t>(entry);
        }
        {  // edge -> the TSEP slots whose block it receives (the sink #E dropped), in (P, k) order
            std::vector<index_t> value, row;
            for (index_t P = 0; P < np; ++P)
                for (int k = 0; k < 4; ++k) {
                    const index_t t = m.target[P][k] >> 1;
                    if (t >= ne) continue;
                    value.push_back(4 * P + k);
                    row.push_back(t);
                }
            build_lists(ne, value.size(), [&](std::size_t k) { return row[k]; }, first, entry, value);
            k_first = DeviceArray<index_t>(first);
            k_entry = DeviceArray<index_t>(entry);
        }
    }
};

// y = K x as a gather: L threads per vertex (consecutive lanes of one warp)
// each pull every L-th of its incident edges' terms, then the L partial sums
// are added in a fixed shuffle order. Every thread of the grid reaches the
// shuffles (those past the last vertex with zeros).
template <int L, class S>
__global__ void edge_multiply_kernel(index_t nv, const index_t* __restrict__ first, const index_t* __restrict__ inc,
                                     const index_t* __restrict__ edge, const S* __restrict__ K,
                                     const S* __restrict__ x, S* __restrict__ y) {
    const std::size_t t = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
    const std::size_t v = t / L;
    const int lane = int(t % L);
    S acc[3] = {0, 0, 0};
    if (v < std::size_t(nv))
        for (index_t j = first[v] + lane; j < first[v + 1]; j += L) {
            const std::size_t e = std::size_t(inc[j] >> 1);
            const bool second = inc[j] & 1;
            const std::size_t a = std::size_t(edge[2 * e]), b = std::size_t(edge[2 * e + 1]);
            const S* k = &K[9 * e];
            const S d0 = x[3 * a] - x[3 * b], d1 = x[3 * a + 1] - x[3 * b + 1], d2 = x[3 * a + 2] - x[3 * b + 2];
            for (int i = 0; i < 3; ++i) {
                if (second)
                    acc[i] += physics::transpose_times(k[i], k[3 + i], k[6 + i], d0, d1, d2);
                else
                    acc[i] -= physics::row_times(k[3 * i], k[3 * i + 1], k[3 * i + 2], d0, d1, d2);
            }
        }
    if constexpr (L > 1)
        for (int off = L / 2; off > 0; off /= 2)
            for (int i = 0; i < 3; ++i) acc[i] += __shfl_down_sync(0xffffffffu, acc[i], off, L);
    if (lane == 0 && v < std::size_t(nv))
        for (int i = 0; i < 3; ++i) y[3 * v + i] = acc[i];
}

// Each edge's K block: its own term and the TSEP blocks that target it
// (first/src: the stiffness gather lists; null for SN). L threads per edge
// (consecutive lanes of one warp): lane 0 starts from the own term, each
// lane adds every L-th TSEP block in registers, then the L partial blocks
// are added in a fixed shuffle order. (One thread per edge, summing
// through K in memory, took 5.9 ms for bunny-1m on an H100; in registers
// 2.0 ms; on 8 lanes: docs/gpu.md.)
inline constexpr int kStiffnessLanes = 8;

template <int L, class S>
__global__ void edge_stiffness_kernel(index_t ne, const index_t* __restrict__ first, const index_t* __restrict__ src,
                                      const index_t* __restrict__ e0, const index_t* __restrict__ e1,
                                      const index_t* __restrict__ target, const S* __restrict__ LE,
                                      const S* __restrict__ LP, const S* __restrict__ p,
                                      const double* __restrict__ g, bool definite, S* __restrict__ K) {
    const std::size_t t = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x;
    const std::size_t e = t / L;
    const int lane = int(t % L);
    S k[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    if (e < std::size_t(ne)) {
        if (lane == 0) physics::edge_stiffness(LE[e], S(physics::stiffness_g(g[e], definite)), &p[3 * e], k);
        if (first != nullptr)
            for (index_t s = first[e] + lane; s < first[e + 1]; s += L) {
                const index_t P = src[s] >> 2, slot = src[s] & 3;
                const index_t tg = target[4 * std::size_t(P) + slot];
                const S* ends[2] = {&p[3 * std::size_t(e0[P])], &p[3 * std::size_t(e1[P])]};
                physics::add_pair_block(physics::slot_coefficient(physics::pair_coefficient(LP[P]), int(slot)),
                                        ends[tg & 1], ends[(tg & 1) ^ 1], k);
            }
    }
    if constexpr (L > 1)
        for (int off = L / 2; off > 0; off /= 2)
            for (int i = 0; i < 9; ++i) k[i] += __shfl_down_sync(0xffffffffu, k[i], off, L);
    if (lane == 0 && e < std::size_t(ne))
        for (int i = 0; i < 9; ++i) K[9 * e + i] = k[i];
}

// p~, zeta and g (double) of one evaluation, and the energy terms.
template <class S>
struct DeviceEdgeState {
    DeviceArray<S> p, zeta;
    DeviceArray<double> g, w;
    void resize(index_t ne) {
        p.resize(3 * std::size_t(ne));
        zeta.resize(ne);
        g.resize(ne);
        w.resize(ne);
    }
};

template <class S, ModelKind Kind>
class DeviceEdgeOperator final : public ElasticOperator<S> {
public:
    DeviceEdgeOperator(const Mesh& mesh, const Materials& materials, int lanes)
        : lanes_(lanes), tets_(mesh), m_(model(mesh, materials), Kind == ModelKind::FE) {
        state_.resize(m_.ne);
        K_.resize(9 * std::size_t(m_.ne));
    }
    index_t num_vertices() const override { return m_.nv; }
    double forces(const S* u, S* f, bool energy) override {
        evaluated_ = true;
        return evaluate(u, f, energy, state_);
    }
    double energy(const S* u) override {
        energy_state_.resize(m_.ne);
        scratch_.resize(3 * std::size_t(m_.nv));
        return evaluate(u, scratch_.data(), true, energy_state_);
    }
    void build_stiffness(bool definite) override {
        if (!evaluated_) throw Error("build_stiffness: forces() has not been called");
        const unsigned blocks = unsigned((std::size_t(m_.ne) * kStiffnessLanes + kThreads - 1) / kThreads);
        if (blocks == 0) return;
        // (SN: no TSEP lists, their pointers are null.)
        edge_stiffness_kernel<kStiffnessLanes><<<blocks, kThreads>>>(
            m_.ne, m_.k_first.data(), m_.k_entry.data(), m_.pair_e0.data(), m_.pair_e1.data(), m_.target.data(),
            m_.LE.data(), m_.LP.data(), state_.p.data(), state_.g.data(), definite, K_.data());
        check_launch("edge_stiffness_kernel");
    }
    void multiply(const S* x, S* y) const override {
        const int lanes = lanes_;
        const index_t *first = m_.v_first.data(), *inc = m_.v_entry.data(), *edge = m_.edge.data();
        const S* K = K_.data();
        if (lanes == 0) {
            multiply_atomic(x, y);
            return;
        }
        const std::size_t threads = std::size_t(m_.nv) * std::size_t(lanes);
        const unsigned blocks = unsigned((threads + kThreads - 1) / kThreads);
        if (blocks == 0) return;
        if (lanes == 8)
            edge_multiply_kernel<8><<<blocks, kThreads>>>(m_.nv, first, inc, edge, K, x, y);
        else if (lanes == 4)
            edge_multiply_kernel<4><<<blocks, kThreads>>>(m_.nv, first, inc, edge, K, x, y);
        else
            edge_multiply_kernel<1><<<blocks, kThreads>>>(m_.nv, first, inc, edge, K, x, y);
        check_launch("edge_multiply_kernel");
    }
    // One thread per edge, adding its two terms into y with atomics: the
    // sums' order, and so their last bits, change from run to run.
    void multiply_atomic(const S* x, S* y) const {
        const index_t* edge = m_.edge.data();
        const S* K = K_.data();
        check(cudaMemsetAsync(y, 0, 3 * std::size_t(m_.nv) * sizeof(S)), "cudaMemsetAsync");
        launch_.each(std::size_t(m_.ne), [=] __device__(std::size_t e) {
            const std::size_t a = std::size_t(edge[2 * e]), b = std::size_t(edge[2 * e + 1]);
            const S* k = &K[9 * e];
            const S d0 = x[3 * a] - x[3 * b], d1 = x[3 * a + 1] - x[3 * b + 1], d2 = x[3 * a + 2] - x[3 * b + 2];
            for (int i = 0; i < 3; ++i) {
                atomicAdd(&y[3 * a + i], -physics::row_times(k[3 * i], k[3 * i + 1], k[3 * i + 2], d0, d1, d2));
                atomicAdd(&y[3 * b + i], physics::transpose_times(k[i], k[3 + i], k[6 + i], d0, d1, d2));
            }
        });
    }
    void diagonal_blocks(S* D) const override {
        const index_t *first = m_.v_first.data(), *inc = m_.v_entry.data();
        const S* K = K_.data();
        launch_.each(std::size_t(m_.nv), [=] __device__(std::size_t v) {
            S d[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
            for (index_t j = first[v]; j < first[v + 1]; ++j) {
                const S* k = &K[9 * std::size_t(inc[j] >> 1)];
                if (inc[j] & 1)
                    physics::subtract_block_transposed(k, d);
                else
                    physics::subtract_block(k, d);
            }
            for (int i = 0; i < 9; ++i) D[9 * v + i] = d[i];
        });
    }
    void for_each_block(void (*visit)(void*, index_t, index_t, const S*), void* ctx) const override {
        DeviceArray<S> Dd(9 * std::size_t(m_.nv));
        diagonal_blocks(Dd.data());
        const std::vector<S> D = Dd.to_host(), K = K_.to_host();
        visit_edge_blocks(m_.edge_host, K.data(), D, [&](index_t i, index_t j, const S* b) { visit(ctx, i, j, b); });
    }
    index_t inverted_tets(const S* u) const override { return tets_.inverted(launch_, u); }

    static EdgeModel<S> model(const Mesh& mesh, const Materials& materials) {
        const Topology topo = build_topology(mesh);
        return make_edge_model<S>(topo, compute_coefficients(mesh, topo, materials));
    }
    // Public only because nvcc's extended lambdas may not sit in a private
    // member function.
    double evaluate(const S* u, S* f, bool energy, DeviceEdgeState<S>& st) const {
        st.resize(m_.ne);
        const index_t* edge = m_.edge.data();
        const S *rest = m_.rest.data(), *LE = m_.LE.data(), *LP = m_.LP.data();
        S *p = st.p.data(), *zeta = st.zeta.data();
        double *g = st.g.data(), *w = st.w.data();
        launch_.each(std::size_t(m_.ne), [=] __device__(std::size_t e) {
            const std::size_t a = std::size_t(edge[2 * e]), b = std::size_t(edge[2 * e + 1]);
            const S* r = &rest[3 * e];
            S* q = &p[3 * e];
            zeta[e] = physics::edge_strain(u[3 * a] - u[3 * b], u[3 * a + 1] - u[3 * b + 1], u[3 * a + 2] - u[3 * b + 2],
                                           r[0], r[1], r[2], q[0], q[1], q[2]);
        });
        const index_t *gfirst = m_.g_first.data(), *gentry = m_.g_entry.data(), *e0 = m_.pair_e0.data(),
                      *e1 = m_.pair_e1.data();
        launch_.each(std::size_t(m_.ne), [=] __device__(std::size_t e) {
            double ge = physics::own_g(LE[e], zeta[e]);
            if (gfirst != nullptr)  // SN: no TSEP lists
                for (index_t j = gfirst[e]; j < gfirst[e + 1]; ++j) {
                    const index_t P = gentry[j] >> 1;
                    const index_t other = (gentry[j] & 1) ? e0[P] : e1[P];
                    ge += physics::pair_g(double(LP[P]), double(zeta[other]));
                }
            g[e] = ge;
            w[e] = physics::energy_term(double(zeta[e]), ge);
        });
        const index_t *first = m_.v_first.data(), *inc = m_.v_entry.data();
        launch_.each(std::size_t(m_.nv), [=] __device__(std::size_t v) {
            S acc[3] = {0, 0, 0};
            for (index_t j = first[v]; j < first[v + 1]; ++j) {
                const std::size_t e = std::size_t(inc[j] >> 1);
                for (int r = 0; r < 3; ++r) {
                    const S t = physics::edge_force(p[3 * e + r], S(g[e]));
                    if (inc[j] & 1)
                        acc[r] -= t;
                    else
                        acc[r] += t;
                }
            }
            for (int r = 0; r < 3; ++r) f[3 * v + r] = acc[r];
        });
        if (!energy) return 0.0;
        return physics::energy_from_terms(launch_.sum(std::size_t(m_.ne), [=] __device__(std::size_t e) { return w[e]; }));
    }

private:
    int lanes_;  // CudaOptions::multiply_lanes
    DeviceLaunch launch_;
    DeviceTets tets_;
    DeviceEdgeModel<S> m_;
    DeviceEdgeState<S> state_, energy_state_;
    DeviceArray<S> K_;  // 9 #E
    DeviceArray<S> scratch_;
    bool evaluated_ = false;
};

}  // namespace edge_detail

using edge_detail::DeviceEdgeOperator;

template <class S>
std::unique_ptr<ElasticOperator<S>> make_device_edge_operator(const Mesh& mesh, const Materials& materials,
                                                              ModelKind model, int lanes) {
    if (model == ModelKind::SN) return std::make_unique<DeviceEdgeOperator<S, ModelKind::SN>>(mesh, materials, lanes);
    return std::make_unique<DeviceEdgeOperator<S, ModelKind::FE>>(mesh, materials, lanes);
}

template std::unique_ptr<ElasticOperator<double>> make_device_edge_operator<double>(const Mesh&, const Materials&,
                                                                                   ModelKind, int);
template std::unique_ptr<ElasticOperator<float>> make_device_edge_operator<float>(const Mesh&, const Materials&,
                                                                                 ModelKind, int);

}  // namespace edgefem::cuda
