// The tet-local form of the edge-based model: per tet, the global ids of its
// 6 edges and the off-diagonal part of the symmetric 6x6 form A(T) whose
// sums over tets are L(P) (formulation.md section 4). The diagonal, summed
// into L(E), stays with the edges: the edge loops add L(E) zeta to g and
// -2 L(E) p~ p~^T to K(E) as before, and A_kk reaches no other block.
//
// Why a second form: the mesh-wide TSEP list scatters every pair's 3x3 block
// into 4 targets (~36 block read-modify-writes per tet). Per tet, the 6
// off-diagonal blocks of the Hessian are
//     K_ab = 2 sum_{k ni a} sum_{l ni b} s_ka s_lb A_kl p~_k p~_l^T
// (s_ka = +1 when a is V0 of edge k, -1 when it is V1), computed in
// registers and scattered once each: 6 block updates per tet.
//
// Layout: tets in batches of kTetLanes<S>, structure-of-arrays inside a batch,
// so the per-tet arithmetic runs across the batch's tets in SIMD lanes;
// tets sorted by their vertices, so neighbouring tets update neighbouring
// K(E) blocks (with the lanes of 16 consecutive batches interleaved, so the
// tets of one batch rarely share an edge).
// Each tet's vertices are taken in ascending global order, so every local
// edge (i < j) runs the way its global edge does (V0 < V1): no transposes.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "edgefem/core/coefficients.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/physics/tet_local_form.hpp"

namespace edgefem {

// Tets per batch: one 32-byte vector of S per value. Measured on bunny-4k
// and armadillo-7k (bench_kernels, 1 thread): double with 4 lanes builds K
// in 47-50 ns/tet against 60-62 with 8 (twice the registers per value spill
// the 72 W vectors), and float keeps 8 (29-34 against 41-43 with 4; its
// scatter transposes 4 x 4 lanes in registers).
template <class S>
inline constexpr int kTetLanes = std::is_same_v<S, float> ? 8 : 4;

// Row of A_kl in a batch: the upper triangle without the diagonal, row by
// row (kSym[k][k] = -1: the kernels take the diagonal as zero, it stays with
// the edges). A 16th row of zeros, read for the diagonal, kept the loops
// plain but streamed 8 more bytes per tet (double): dropped.
inline constexpr int kFormRows = 15;
inline constexpr int kSym[6][6] = {{-1, 0, 1, 2, 3, 4},  {0, -1, 5, 6, 7, 8},   {1, 5, -1, 9, 10, 11},
                                   {2, 6, 9, -1, 12, 13}, {3, 7, 10, 12, -1, 14}, {4, 8, 11, 13, 14, -1}};

// One tile of the serial sweeps (tet_form_forces, tet_form_stiffness_all).
// Tile i runs the edge loop up to edge edge_end, the batches up to
// batch_end, then (forces) zeroes f up to vertex zero_end and scatters the
// vertex segments up to vertex_end. Its batches touch only edges below
// edge_end, and an edge's g is final once every batch whose lowest vertex is
// at most its V0 has run, so each value is computed from the same inputs in
// the same order as by three whole-mesh passes: the results are bitwise
// equal, but on meshes larger than the cache a tile's p~, zeta and g (or
// K(E)) are still cached when the next pass reads them.
// bench: bunny-1m force 23-26 -> 19-21 ns/tet at 1024 batches per tile
// (256: 21-22; 16384: 20-21; whole mesh: 23-32); bunny-4k unchanged.
struct FormTile {
    index_t batch_end, edge_end, vertex_end, zero_end;
};
inline constexpr index_t kFormTileBatches = 1024;

template <class S>
struct TetEdgeForm {
    index_t num_tets = 0;
    index_t num_edges = 0;
    // Batch b, local edge k, lane l: edge[(b * 6 + k) * kTetLanes<S> + l]. Lanes
    // past num_tets in the last batch repeat lane 0's edges, with A = 0.
    std::vector<index_t> edge;
    // A[(b * kFormRows + kSym[k][l]) * kTetLanes<S> + lane].
    std::vector<S> A;
    // The tet in each slot (batch * kTetLanes<S> + lane), for inspection only:
    // the kernels never read it. Tets are stored sorted by their vertices,
    // the lanes of 16 consecutive batches interleaved (tet_edge_form.cpp).
    std::vector<index_t> slot_tet;
    // The serial sweeps' tiles (FormTile); empty: one tile, the whole mesh.
    std::vector<FormTile> tiles;

    index_t num_batches() const { return (num_tets + kTetLanes<S> - 1) / kTetLanes<S>; }
    index_t batch_size(index_t b) const { return std::min<index_t>(kTetLanes<S>, num_tets - b * kTetLanes<S>); }
    double bytes_per_tet() const {
        return num_tets > 0 ? double(edge.size() * sizeof(index_t) + A.size() * sizeof(S)) / num_tets : 0.0;
    }
};

// The same form in another scalar type (e.g. the operation-counting one).
template <class To, class From>
TetEdgeForm<To> convert_scalar(const TetEdgeForm<From>& f) {
    static_assert(kTetLanes<To> == kTetLanes<From>, "the batch layout depends on the lane count");
    TetEdgeForm<To> c;
    c.num_tets = f.num_tets;
    c.num_edges = f.num_edges;
    c.edge = f.edge;
    c.A.assign(f.A.begin(), f.A.end());
    c.slot_tet = f.slot_tet;
    c.tiles = f.tiles;
    return c;
}

// Throws InvalidArgument for an invalid material. The tiles are planned
// with kFormTileBatches batches each.
template <class S>
TetEdgeForm<S> make_tet_edge_form(const Mesh& mesh, const Topology& topo, const Materials& materials);

// Tiles of `batches_per_tile` batches (>= 1) for `form` over the edge list
// its edge ids index: {V0, V1} per edge, sorted by V0, with first_edge[v]
// the first edge whose V0 is v (as in Topology).
template <class S>
std::vector<FormTile> plan_form_tiles(const TetEdgeForm<S>& form, const std::vector<std::array<index_t, 2>>& edges,
                                      const std::vector<index_t>& first_edge, index_t batches_per_tile);

// A stretch of the sweep (the owner variant's parts, parallel/): batches
// [batch_begin, batch_end); the edge loop starts at edge_begin and stops at
// edge_end (later edges are another part's), the scatter starts at vertex
// vertex_begin and stops at vertex_end. The last tile ends at batch_end,
// edge_end and vertex_end.
struct FormTileRange {
    index_t batch_begin, batch_end, edge_begin, edge_end, vertex_begin, vertex_end;
};
// The tiles of one stretch (the overload above: the whole mesh, after
// checking the edge list). Throws InvalidArgument for a range outside the
// form, the edges or the vertices.
template <class S>
std::vector<FormTile> plan_form_tiles(const TetEdgeForm<S>& form, const std::vector<std::array<index_t, 2>>& edges,
                                      const std::vector<index_t>& first_edge, index_t batches_per_tile,
                                      const FormTileRange& range);

namespace kernel {

// kTetLanes<S> values of S, one per tet of a batch: a GCC/Clang vector for
// built-in scalars (the arithmetic runs in SIMD registers), and for other
// scalars (the operation-counting scalar of bench/counting_scalar.hpp) an
// array with the same element-wise operators, so the same kernel source
// runs on both.
template <class S>
struct LaneArray {
    S v[kTetLanes<S>] = {};
    S& operator[](int l) { return v[l]; }
    const S& operator[](int l) const { return v[l]; }
    friend LaneArray operator+(const LaneArray& a, const LaneArray& b) {
        LaneArray r;
        for (int l = 0; l < kTetLanes<S>; ++l) r.v[l] = a.v[l] + b.v[l];
        return r;
    }
    friend LaneArray operator*(const LaneArray& a, const LaneArray& b) {
        LaneArray r;
        for (int l = 0; l < kTetLanes<S>; ++l) r.v[l] = a.v[l] * b.v[l];
        return r;
    }
    friend LaneArray operator*(const S& a, const LaneArray& b) {
        LaneArray r;
        for (int l = 0; l < kTetLanes<S>; ++l) r.v[l] = a * b.v[l];
        return r;
    }
    LaneArray& operator+=(const LaneArray& b) {
        for (int l = 0; l < kTetLanes<S>; ++l) v[l] += b.v[l];
        return *this;
    }
};
template <class S, bool = std::is_arithmetic_v<S>>
struct Lanes {
    typedef S type __attribute__((vector_size(sizeof(S) * kTetLanes<S>)));
};
template <class S>
struct Lanes<S, false> {
    using type = LaneArray<S>;
};

// L doubles in one GCC/Clang vector (a class template: the attribute on a
// typedef whose size depends on a template parameter is ignored inside a
// function template).
template <int L>
struct DoubleLanes {
    typedef double type __attribute__((vector_size(sizeof(double) * L)));
};

// Adds each tet's share of sum_{F != E} A_EF zeta(F) to g(E) for batch b
// (g in double whatever S is, as EdgeState::g). The lanes run in groups of
// 4 (one 32-byte vector of double): float's 8-lane batches as two groups
// (bench_kernels, float force: 12.9 against 17.1 ns/tet on bunny-4k with
// all 8 lanes in two-register vectors).
// With `Spill`, g(e) for e >= end goes to spill[e - end] (the owner-computes
// parallel variant's window past its part). The serial form keeps plain
// restrict-qualified g updates: through kernel::ForwardOut or a lambda it
// measured 5-10 % slower.
// zeta and g of edge e sit at slot(e) (Spill: EdgeSlot only).
template <bool Spill, class S, class Slot = EdgeSlot>
inline void tet_form_strain_impl(const TetEdgeForm<S>& f, index_t b, const S* __restrict zeta, double* __restrict g,
                                 double* __restrict spill, index_t end, Slot slot = {}) {
    static_assert(!Spill || std::is_same_v<Slot, EdgeSlot>, "spill windows index the mesh-wide state");
    constexpr int L = kTetLanes<S>, G = L < 4 ? L : 4;
    using V = typename DoubleLanes<G>::type;
    const auto add = [&](index_t e, double v) {
        if constexpr (Spill)
            (e < end ? g[e] : spill[e - end]) += v;
        else
            g[slot(e)] += v;
    };
    const int n = f.batch_size(b);
    for (int h = 0; h < n; h += G) {
        const index_t* E = &f.edge[std::size_t(b) * 6 * L + h];
        const S* A = &f.A[std::size_t(b) * kFormRows * L + h];
        V Z[6];
        for (int k = 0; k < 6; ++k) {
            double z[G];  // lanes through an array: per-lane writes into Z[k] warn (-Wmaybe-uninitialized)
            for (int l = 0; l < G; ++l) z[l] = double(zeta[slot(E[k * L + l])]);
            __builtin_memcpy(&Z[k], z, sizeof(V));
        }
        const auto coef = [&](int k, int m) {
            double a[G];
            for (int l = 0; l < G; ++l) a[l] = double(A[kSym[k][m] * L + l]);
            V av;
            __builtin_memcpy(&av, a, sizeof(V));
            return av;
        };
#pragma GCC unroll 6
        for (int k = 0; k < 6; ++k) {
            const V s = physics::form_g(k, coef, Z);
            if (n - h >= G) {
#pragma GCC unroll 4
                for (int l = 0; l < G; ++l) add(E[k * L + l], s[l]);
            } else {
                for (int l = 0; l < n - h; ++l) add(E[k * L + l], s[l]);
            }
        }
    }
}
// Non-temporal prefetch of batch b's rows and edge ids (nothing past the
// last batch), for the batch loops to issue kFormPrefetchBatches ahead when
// the form runs in tiles (a mesh larger than the cache; one tile: not
// issued). On such a mesh the form streams through L2 and evicts the zeta,
// g (or K(E)) lines of the tile's live window, which the next tiles read
// again (the RCM front: ~38k edges on bunny-1m); lines fetched
// non-temporally displace little else.
// bench (standalone A/B in one process, 1 thread, RCM, medians of 15-21
// paired rounds): force on bunny-1m 0.96 of the time without, bunny-250k
// 0.98; stiffness on bunny-1m 0.98.
inline constexpr index_t kFormPrefetchBatches = 32;
template <class S>
EDGEFEM_KERNEL void prefetch_form_batch(const TetEdgeForm<S>& f, index_t b) {
    if (b >= f.num_batches()) return;
    constexpr int L = kTetLanes<S>;
    const char* a = reinterpret_cast<const char*>(&f.A[std::size_t(b) * kFormRows * L]);
    for (std::size_t o = 0; o < kFormRows * L * sizeof(S); o += 64) __builtin_prefetch(a + o, 0, 0);
    const char* e = reinterpret_cast<const char*>(&f.edge[std::size_t(b) * 6 * L]);
    for (std::size_t o = 0; o < 6 * L * sizeof(index_t); o += 64) __builtin_prefetch(e + o, 0, 0);
}

template <class S>
inline void tet_form_strain(const TetEdgeForm<S>& f, index_t b, const S* __restrict zeta, double* __restrict g) {
    tet_form_strain_impl<false>(f, b, zeta, g, nullptr, 0);
}
template <class S>
inline void tet_form_strain(const TetEdgeForm<S>& f, index_t b, const S* __restrict zeta, const ForwardOut<double>& out) {
    tet_form_strain_impl<true>(f, b, zeta, out.direct, out.spill, out.end);
}
// The g pass over batches [b0, b1), each batch's rows and ids fetched
// kFormPrefetchBatches ahead; out of line (EDGEFEM_LOOP says why).
template <class S, class Slot>
EDGEFEM_LOOP void tet_form_strain_batches_prefetched(const TetEdgeForm<S>& f, index_t b0, index_t b1,
                                                     const S* __restrict zeta, double* __restrict g, Slot slot) {
    for (index_t b = b0; b < b1; ++b) {
        prefetch_form_batch(f, b + kFormPrefetchBatches);
        tet_form_strain_impl<false>(f, b, zeta, g, nullptr, 0, slot);
    }
}
template <class S>
EDGEFEM_LOOP void tet_form_strain_batches_prefetched(const TetEdgeForm<S>& f, index_t b0, index_t b1,
                                                     const S* __restrict zeta, const ForwardOut<double>& out) {
    for (index_t b = b0; b < b1; ++b) {
        prefetch_form_batch(f, b + kFormPrefetchBatches);
        tet_form_strain(f, b, zeta, out);
    }
}

// blk[l][x] += kv[x][l] for the L lanes and 9 values of a block. In float,
// 4 x 4 transposes in registers turn 9 scalar updates per lane into two
// 4-wide ones and one scalar (37 -> 30 ns/tet on bunny-4k); in double the
// 32-byte updates of 72-byte blocks straddle cache lines and lose (50 -> 58),
// so double stays scalar.
template <class V, class S>
inline void scatter_blocks(const V (&kv)[9], S* const (&blk)[kTetLanes<S>]) {
    if constexpr (!std::is_same_v<S, float>) {
        for (int x = 0; x < 9; ++x)
#pragma GCC unroll 8
            for (int l = 0; l < kTetLanes<S>; ++l) blk[l][x] += kv[x][l];
    } else {
        typedef S V4 __attribute__((vector_size(sizeof(S) * 4)));
        auto add4 = [](S* dst, V4 v) {
            V4 d;
            __builtin_memcpy(&d, dst, sizeof(V4));
            d += v;
            __builtin_memcpy(dst, &d, sizeof(V4));
        };
        static_assert(kTetLanes<S> == 8);
#pragma GCC unroll 2
        for (int h = 0; h < 2; ++h) {
            V4 r[8];
            for (int x = 0; x < 8; ++x)
                r[x] = h == 0 ? __builtin_shufflevector(kv[x], kv[x], 0, 1, 2, 3) : __builtin_shufflevector(kv[x], kv[x], 4, 5, 6, 7);
#pragma GCC unroll 2
            for (int q = 0; q < 2; ++q) {  // values 4q .. 4q + 3
                const V4 t0 = __builtin_shufflevector(r[4 * q], r[4 * q + 1], 0, 4, 1, 5);
                const V4 t1 = __builtin_shufflevector(r[4 * q], r[4 * q + 1], 2, 6, 3, 7);
                const V4 t2 = __builtin_shufflevector(r[4 * q + 2], r[4 * q + 3], 0, 4, 1, 5);
                const V4 t3 = __builtin_shufflevector(r[4 * q + 2], r[4 * q + 3], 2, 6, 3, 7);
                add4(blk[4 * h] + 4 * q, __builtin_shufflevector(t0, t2, 0, 1, 4, 5));
                add4(blk[4 * h + 1] + 4 * q, __builtin_shufflevector(t0, t2, 2, 3, 6, 7));
                add4(blk[4 * h + 2] + 4 * q, __builtin_shufflevector(t1, t3, 0, 1, 4, 5));
                add4(blk[4 * h + 3] + 4 * q, __builtin_shufflevector(t1, t3, 2, 3, 6, 7));
            }
        }
#pragma GCC unroll 8
        for (int l = 0; l < kTetLanes<S>; ++l) blk[l][8] += kv[8][l];
    }
}

// Adds each tet's share of the 6 off-diagonal Hessian blocks, less the edge
// terms, to K(E) (row-major 3x3 per edge, #E + 1 blocks: the last is the
// sink) for batch b, from the current edge vectors p~ (3 #E).
// With `Spill`, the blocks of edges >= end go to spill[9 (e - end)] (the
// owner-computes parallel variant's window past its part); padding lanes
// still write the sink block K(#E).
template <bool Spill, class S>
inline void tet_form_stiffness_impl(const TetEdgeForm<S>& f, index_t b, const S* __restrict p, S* __restrict K,
                                    S* __restrict spill, index_t end) {
    constexpr int L = kTetLanes<S>;
    // One value per lane in a register: the blocks are scattered straight
    // from registers (a stack array written as vectors and re-read per lane
    // stalls every read on store forwarding: measured 2x slower).
    using V = typename Lanes<S>::type;
    const index_t* E = &f.edge[std::size_t(b) * 6 * L];
    const S* A = &f.A[std::size_t(b) * kFormRows * L];
    auto row = [&](int k, int m) {
        V v{};
        if (k == m) return v;  // the diagonal is the edges' (constant after unrolling)
        for (int l = 0; l < L; ++l) v[l] = A[kSym[k][m] * L + l];
        return v;
    };
    V P[6][3];
    for (int k = 0; k < 6; ++k)
        for (int c = 0; c < 3; ++c)
            for (int l = 0; l < L; ++l) P[k][c][l] = p[3 * std::size_t(E[k * L + l]) + c];
    V W[6][4][3];
    physics::form_w<S>(row, P, W);
    // The 6 blocks K_ab (physics::form_block). Padding lanes of the last
    // batch write the sink block K(#E).
    const int n = f.batch_size(b);
    S* const sink = &K[9 * std::size_t(f.num_edges)];
#pragma GCC unroll 6
    for (int e = 0; e < 6; ++e) {
        S* blk[L];
        for (int l = 0; l < L; ++l) {
            const index_t t = E[e * L + l];
            if constexpr (Spill)
                blk[l] = l >= n ? sink : t < end ? &K[9 * std::size_t(t)] : &spill[9 * std::size_t(t - end)];
            else
                blk[l] = l < n ? &K[9 * std::size_t(t)] : sink;
        }
        V kv[9];
        physics::form_block<S>(e, P, W, kv);
        scatter_blocks(kv, blk);
    }
}
template <class S>
inline void tet_form_stiffness(const TetEdgeForm<S>& f, index_t b, const S* __restrict p, S* __restrict K) {
    tet_form_stiffness_impl<false>(f, b, p, K, static_cast<S*>(nullptr), 0);
}
template <class S>
inline void tet_form_stiffness(const TetEdgeForm<S>& f, index_t b, const S* __restrict p, const ForwardOut<S>& out) {
    tet_form_stiffness_impl<true>(f, b, p, out.direct, out.spill, out.end);
}
// The stiffness pair terms of batches [b0, b1) with the rows and ids fetched
// ahead (as tet_form_strain_batches_prefetched), into K or through `out`.
template <class S>
EDGEFEM_LOOP void tet_form_stiffness_batches_prefetched(const TetEdgeForm<S>& f, index_t b0, index_t b1,
                                                        const S* __restrict p, S* __restrict K) {
    for (index_t b = b0; b < b1; ++b) {
        prefetch_form_batch(f, b + kFormPrefetchBatches);
        tet_form_stiffness(f, b, p, K);
    }
}
template <class S>
EDGEFEM_LOOP void tet_form_stiffness_batches_prefetched(const TetEdgeForm<S>& f, index_t b0, index_t b1,
                                                        const S* __restrict p, const ForwardOut<S>& out) {
    for (index_t b = b0; b < b1; ++b) {
        prefetch_form_batch(f, b + kFormPrefetchBatches);
        tet_form_stiffness(f, b, p, out);
    }
}

}  // namespace kernel

// ---- Serial loops: edge_forces / edge_stiffness_all with the TSEP loop
// replaced by the tet-local form (same results up to summation order). ----

// Runs `body(tile, e0, b0, a0, z0)` for each tile (FormTile) with the ends
// of the previous one, the whole mesh as one tile when the form has none.
template <class S, class Body>
void for_form_tiles(const TetEdgeForm<S>& form, index_t num_edges, index_t num_vertices, Body&& body) {
    const FormTile whole{form.num_batches(), num_edges, num_vertices, num_vertices};
    const FormTile* t = form.tiles.empty() ? &whole : form.tiles.data();
    const std::size_t n = form.tiles.empty() ? 1 : form.tiles.size();
    FormTile prev{0, 0, 0, 0};
    for (std::size_t i = 0; i < n; ++i) {
        body(t[i], prev);
        prev = t[i];
    }
}

// The three passes (edge loop, g pass over the batches, edge scatter) run
// tile by tile (FormTile), on state arrays indexed through `slot`. The g
// pass and the scatter were also tried fused in one sweep over the
// vertices: 5-10 % slower on bunny-4k and armadillo-7k (bench_kernels,
// three runs).
template <ModelKind Kind, bool Energy, class S, class Slot>
double tet_form_forces_on(const EdgeModel<S>& m, const TetEdgeForm<S>& form, const S* u, S* f, S* p, S* zeta,
                          double* g, Slot slot) {
    double W = 0;
    const bool tiled = form.tiles.size() > 1;
    const kernel::ForwardOut<S> out = kernel::direct_only(f);
    for_form_tiles(form, m.num_edges(), m.num_vertices, [&](const FormTile& t, const FormTile& prev) {
        kernel::edge_strain_range(m, u, prev.edge_end, t.edge_end, p, zeta, g, slot);
        if constexpr (Kind == ModelKind::FE) {
            if (tiled)
                kernel::tet_form_strain_batches_prefetched(form, prev.batch_end, t.batch_end, zeta, g, slot);
            else
                for (index_t b = prev.batch_end; b < t.batch_end; ++b)
                    kernel::tet_form_strain_impl<false>(form, b, zeta, g, nullptr, 0, slot);
        }
        std::fill(f + 3 * std::size_t(prev.zero_end), f + 3 * std::size_t(t.zero_end), S(0));
        // (The plain call for the stored state: through `out` and the slot
        // it measured 1-4 % slower on armadillo-7k.)
        if constexpr (std::is_same_v<Slot, EdgeSlot>)
            for (index_t a = prev.vertex_end; a < t.vertex_end; ++a) kernel::edge_force_segment(m, a, p, g, f);
        else
            for (index_t a = prev.vertex_end; a < t.vertex_end; ++a) kernel::edge_force_segment(m, a, p, g, f, out, slot);
        if constexpr (Energy)
            for (index_t e = m.edge_first[prev.vertex_end]; e < m.edge_first[t.vertex_end]; ++e)
                W += physics::energy_term(double(zeta[slot(e)]), g[slot(e)]);
    });
    return physics::energy_from_terms(W);
}

// Forces (and the energy when `Energy`); leaves p~, zeta, g in `st` for
// tet_form_stiffness_all.
template <ModelKind Kind, bool Energy, class S>
double tet_form_forces(const EdgeModel<S>& m, const TetEdgeForm<S>& form, const S* u, S* f, EdgeState<S>& st) {
    st.resize(m.num_edges());
    return tet_form_forces_on<Kind, Energy>(m, form, u, f, st.p.data(), st.zeta.data(), st.g.data(), EdgeSlot{});
}

// The edge state of a force call that keeps none: a ring of a power of two
// slots (edge e at e & mask), at least as long as the longest stretch of
// edges alive at once in the tiles (from the first edge of the first
// segment still to scatter to the last edge strained). On a mesh larger
// than the cache the mesh-wide state is written back to memory after each
// tile (40 bytes per edge, plus the write-allocate reads); the ring stays
// cached. Empty (unused) when the form has one tile or the ring would not
// be shorter than the edge list.
template <class S>
struct FormRing {
    RingSlot slot{0};
    std::vector<S> p, zeta;
    std::vector<double> g;
    bool empty() const { return g.empty(); }
};
// The longest stretch of edges alive at once in the form's tiles (0 for
// one tile); edge_first as EdgeModel::edge_first.
template <class S>
index_t form_live_edges(const TetEdgeForm<S>& form, const std::vector<index_t>& edge_first) {
    index_t live = 0, first_vertex = 0;
    if (form.tiles.size() > 1)
        for (const FormTile& t : form.tiles) {
            live = std::max(live, t.edge_end - edge_first[first_vertex]);
            first_vertex = t.vertex_end;
        }
    return live;
}
template <class S>
FormRing<S> make_form_ring(const TetEdgeForm<S>& form, const std::vector<index_t>& edge_first) {
    FormRing<S> r;
    const index_t live = form_live_edges(form, edge_first);
    if (live == 0) return r;
    index_t n = 1;
    while (n < live) n *= 2;
    if (n >= form.num_edges) return r;
    r.slot = RingSlot{n - 1};
    r.p.resize(3 * std::size_t(n));
    r.zeta.resize(n);
    r.g.resize(n);
    return r;
}

// tet_form_forces without the state: the same operations in the same order
// (bitwise the same forces and energy) on the ring; a stiffness needs
// tet_form_forces. bench (standalone, 1 thread, RCM, medians of 21 paired
// rounds): bunny-1m 0.93-0.95 of tet_form_forces' time.
template <ModelKind Kind, bool Energy, class S>
double tet_form_forces_ring(const EdgeModel<S>& m, const TetEdgeForm<S>& form, const S* u, S* f, FormRing<S>& ring) {
    // O(tiles) per call: a ring made for other tiles would overwrite live slots.
    const index_t live = form_live_edges(form, m.edge_first);
    if (ring.empty() || live == 0 || live > ring.slot.mask + 1)
        throw InvalidArgument("tet_form_forces_ring: the ring does not fit the form's tiles (make_form_ring)");
    return tet_form_forces_on<Kind, Energy>(m, form, u, f, ring.p.data(), ring.zeta.data(), ring.g.data(), ring.slot);
}

template <ModelKind Kind, bool Definite = false, class S>
void tet_form_stiffness_all(const EdgeModel<S>& m, const TetEdgeForm<S>& form, const EdgeState<S>& st,
                            EdgeStiffness<S>& K) {
    const index_t ne = m.num_edges();
    if (K.K.size() != 9 * (std::size_t(ne) + 1)) K.resize(ne);
    const S* p = st.p.data();
    const double* g = st.g.data();
    S* Kv = K.K.data();
    const bool tiled = form.tiles.size() > 1;
    for_form_tiles(form, ne, m.num_vertices, [&](const FormTile& t, const FormTile& prev) {
        for (index_t e = prev.edge_end; e < t.edge_end; ++e) kernel::edge_stiffness<Definite>(m, e, p, g, Kv);
        if constexpr (Kind == ModelKind::FE) {
            if (tiled)
                kernel::tet_form_stiffness_batches_prefetched(form, prev.batch_end, t.batch_end, p, Kv);
            else
                for (index_t b = prev.batch_end; b < t.batch_end; ++b) kernel::tet_form_stiffness(form, b, p, Kv);
        }
    });
}

extern template struct TetEdgeForm<double>;
extern template struct TetEdgeForm<float>;
extern template TetEdgeForm<double> make_tet_edge_form<double>(const Mesh&, const Topology&, const Materials&);
extern template TetEdgeForm<float> make_tet_edge_form<float>(const Mesh&, const Topology&, const Materials&);

}  // namespace edgefem
