// Worker variants of the edge kernels for the parallel back-ends'
// alternatives to the coloured scatter (parallel/): the same formulas as
// edge_kernels.hpp, written
//   * as gathers: one worker call computes one target (a vertex's force, an
//     edge's g or K block, a vertex's K x row) from a list of its sources,
//     so that threads never write the same address (no colouring, no
//     atomics); and
//   * as scatters through an accumulator `add(index, value)` (for atomic
//     scatter; the private-accumulator variant runs the plain workers of
//     edge_kernels.hpp on per-thread buffers).
// The source lists are precomputed by the caller (parallel/ builds them once
// per mesh). Given in ascending source order, the gathers add their terms in
// the order the serial loops of edge_kernels.hpp do.
#pragma once

#include <cstdint>

#include "cpu/edge_kernels.hpp"

namespace edgefem::kernel {

// ---- Gather workers ---------------------------------------------------------

// Incident-edge lists for the vertex gathers encode the side of the vertex:
// item = (e << 1) | 1 when v = V1(e), (e << 1) when v = V0(e).
inline constexpr index_t incident_edge(index_t item) { return item >> 1; }
inline constexpr bool incident_is_v1(index_t item) { return (item & 1) != 0; }

// f(v) = sum_{E: V0=v} p~ g - sum_{E: V1=v} p~ g over v's incident edges
// (overwrites f(v)).
template <class S>
inline void vertex_force_gather(index_t v, const index_t* __restrict incident, index_t n, const S* __restrict p,
                                const double* __restrict g, S* __restrict f) {
    S acc[3] = {S(0), S(0), S(0)};
    for (index_t k = 0; k < n; ++k) {
        const index_t e = incident_edge(incident[k]);
        const S s = S(g[e]);
        const S* q = &p[3 * std::size_t(e)];
        if (incident_is_v1(incident[k]))
            for (int r = 0; r < 3; ++r) acc[r] -= physics::edge_force(q[r], s);
        else
            for (int r = 0; r < 3; ++r) acc[r] += physics::edge_force(q[r], s);
    }
    for (int r = 0; r < 3; ++r) f[3 * std::size_t(v) + r] = acc[r];
}

// g(e) += the TSEP terms of edge e: L(P) zeta(E0) for the TSEPs with E1 = e
// (given as in_e0[k] with their L(P) copied to in_L[k], in TSEP order), then
// L(P) zeta(E1) summed over e's own segment (E0 = e).
template <class S>
inline void tsep_strain_gather(const EdgeModel<S>& m, index_t e, const index_t* __restrict in_e0,
                               const S* __restrict in_L, index_t n, const S* __restrict zeta, double* __restrict g) {
    double ge = g[e];
    for (index_t k = 0; k < n; ++k) ge += physics::pair_g(double(in_L[k]), double(zeta[in_e0[k]]));
    double acc = 0;
    for (index_t P = m.tsep_first[e]; P < m.tsep_first[e + 1]; ++P)
        acc += physics::pair_g(double(m.LP[P]), double(zeta[m.tsep_other[P]]));
    g[e] = ge + acc;
}

// An incoming stiffness contribution of edge E2: TSEP P (first edge e0) adds
// its block to K(E2) through slot k; `slot` = k | (transposed << 2).
struct StiffnessSource {
    index_t tsep;
    index_t e0;
    std::uint8_t slot;
};

// K(e2) += its incoming TSEP contributions (physics/tsep_stiffness.hpp),
// in source order.
template <class S>
inline void tsep_stiffness_gather(const EdgeModel<S>& m, index_t e2, const StiffnessSource* __restrict in, index_t n,
                                  const S* __restrict p, S* __restrict K) {
    S* blk = &K[9 * std::size_t(e2)];
    S acc[9];
    for (int i = 0; i < 9; ++i) acc[i] = blk[i];
    for (index_t s = 0; s < n; ++s) {
        const index_t P = in[s].tsep;
        const bool transposed = (in[s].slot & 4) != 0;
        const S* ends[2] = {&p[3 * std::size_t(in[s].e0)], &p[3 * std::size_t(m.tsep_other[P])]};
        physics::add_pair_block(physics::slot_coefficient(physics::pair_coefficient(m.LP[P]), in[s].slot & 3),
                                ends[transposed], ends[!transposed], acc);
    }
    for (int i = 0; i < 9; ++i) blk[i] = acc[i];
}

// y(v) = sum over v's incident edges of -K(E) d (v = V0) or K(E)^T d
// (v = V1), d = x(V0) - x(V1) (overwrites y(v)).
template <class S>
inline void vertex_kx_gather(const EdgeModel<S>& m, index_t v, const index_t* __restrict incident, index_t n,
                             const S* __restrict K, const S* __restrict x, S* __restrict y) {
    S acc[3] = {S(0), S(0), S(0)};
    for (index_t s = 0; s < n; ++s) {
        const index_t e = incident_edge(incident[s]);
        const index_t a = m.edge[e][0], b = m.edge[e][1];
        const S* k = &K[9 * std::size_t(e)];
        const S d[3] = {x[3 * a] - x[3 * b], x[3 * a + 1] - x[3 * b + 1], x[3 * a + 2] - x[3 * b + 2]};
        if (incident_is_v1(incident[s]))
            for (int i = 0; i < 3; ++i) acc[i] += physics::transpose_times(k[i], k[3 + i], k[6 + i], d[0], d[1], d[2]);
        else
            for (int i = 0; i < 3; ++i) acc[i] -= physics::row_times(k[3 * i], k[3 * i + 1], k[3 * i + 2], d[0], d[1], d[2]);
    }
    for (int i = 0; i < 3; ++i) y[3 * std::size_t(v) + i] = acc[i];
}

// D(v) = -sum_{E: V0=v} K(E) - sum_{E: V1=v} K(E)^T (overwrites D(v)).
template <class S>
inline void vertex_diagonal_gather(index_t v, const index_t* __restrict incident, index_t n, const S* __restrict K,
                                   S* __restrict D) {
    S acc[9] = {};
    for (index_t s = 0; s < n; ++s) {
        const S* k = &K[9 * std::size_t(incident_edge(incident[s]))];
        if (incident_is_v1(incident[s]))
            physics::subtract_block_transposed(k, acc);
        else
            physics::subtract_block(k, acc);
    }
    for (int i = 0; i < 9; ++i) D[9 * std::size_t(v) + i] = acc[i];
}

// ---- Scatter workers through an accumulator -----------------------------------
// `add(i, value)` adds value to element i of the output (e.g. an atomic
// fetch_add). The subtractions of the plain workers become additions of the
// negated value, which is the same IEEE operation.

template <class S, class Add>
inline void tsep_strain_segment_to(const EdgeModel<S>& m, index_t e0, const S* __restrict zeta, Add&& add_g) {
    const double z0 = zeta[e0];
    double acc = 0;
    for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P) {
        const index_t e1 = m.tsep_other[P];
        const double L = m.LP[P];
        acc += physics::pair_g(L, double(zeta[e1]));
        add_g(e1, physics::pair_g(L, z0));
    }
    add_g(e0, acc);
}

template <class S, class Add>
inline void edge_force_to(const EdgeModel<S>& m, index_t e, const S* __restrict p, const double* __restrict g,
                          Add&& add) {
    const index_t a = m.edge[e][0], b = m.edge[e][1];
    for (int r = 0; r < 3; ++r) {
        const S v = physics::edge_force(p[3 * std::size_t(e) + r], S(g[e]));
        add(3 * std::size_t(a) + r, v);
        add(3 * std::size_t(b) + r, -v);
    }
}

// As tsep_stiffness_segment; targets at the sink block (#E) are skipped.
template <class S, class Add>
inline void tsep_stiffness_segment_to(const EdgeModel<S>& m, index_t e0, const S* __restrict p, Add&& add) {
    const S* p0 = &p[3 * std::size_t(e0)];
    const index_t sink = m.num_edges();
    for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P) {
        const S* ends[2] = {p0, &p[3 * std::size_t(m.tsep_other[P])]};
        const S c = physics::pair_coefficient(m.LP[P]);
        for (int k = 0; k < 4; ++k) {
            const index_t t = m.target[P][k];
            if ((t >> 1) >= sink) continue;
            S kp[9] = {};
            physics::add_pair_block(physics::slot_coefficient(c, k), ends[t & 1], ends[(t & 1) ^ 1], kp);
            const std::size_t blk = 9 * std::size_t(t >> 1);
            for (int i = 0; i < 9; ++i) add(blk + i, kp[i]);
        }
    }
}

template <class S, class Add>
inline void edge_kx_to(const EdgeModel<S>& m, index_t e, const S* __restrict K, const S* __restrict x, Add&& add) {
    const index_t a = m.edge[e][0], b = m.edge[e][1];
    const S* k = &K[9 * std::size_t(e)];
    const S d[3] = {x[3 * a] - x[3 * b], x[3 * a + 1] - x[3 * b + 1], x[3 * a + 2] - x[3 * b + 2]};
    for (int i = 0; i < 3; ++i) {
        add(3 * std::size_t(a) + i, -physics::row_times(k[3 * i], k[3 * i + 1], k[3 * i + 2], d[0], d[1], d[2]));
        add(3 * std::size_t(b) + i, physics::transpose_times(k[i], k[3 + i], k[6 + i], d[0], d[1], d[2]));
    }
}

template <class S, class Add>
inline void edge_diagonal_to(const EdgeModel<S>& m, index_t e, const S* __restrict K, Add&& add) {
    const S* k = &K[9 * std::size_t(e)];
    S d0[9] = {}, d1[9] = {};
    physics::subtract_block(k, d0);
    physics::subtract_block_transposed(k, d1);
    for (int q = 0; q < 9; ++q) {
        add(9 * std::size_t(m.edge[e][0]) + q, d0[q]);
        add(9 * std::size_t(m.edge[e][1]) + q, d1[q]);
    }
}

}  // namespace edgefem::kernel
