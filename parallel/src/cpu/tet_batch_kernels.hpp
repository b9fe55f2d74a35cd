// The per-tet force and stiffness for the 4 tets of a TetBatch at once, one
// tet per SIMD lane: the arithmetic of kernel::tet_force and
// tet_stiffness with every scalar a 4-lane vector (built-in scalars
// only). Within one tet only 3 of 4 lanes ever did work, and the 3x3
// products needed lane shuffles; across tets every lane works and none does.
// Prototype, bunny-4k, double, 1 thread: force 26.1 -> 11.1 ns per tet.
#pragma once

#include <array>
#include <cstring>
#include <type_traits>

#include "cpu/kernel_inline.hpp"
#include "cpu/tet_batches.hpp"
#include "edgefem/physics/tet_stvk.hpp"

namespace edgefem {

namespace kernel {

// H = Du Dm^-1 and the volume-scaled S of a batch's tets
// (physics::tet_deformation, one tet per lane).
template <class S>
using BatchDeformation = physics::TetDeformation<typename TetBatch<S>::V>;

template <bool Energy, class S>
EDGEFEM_KERNEL void batch_deformation(const TetBatch<S>& bt, const S* __restrict u, BatchDeformation<S>& d) {
    using V = typename TetBatch<S>::V;
    V U[4][3];  // scalar loads into lanes: u needs no padding
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r)
            U[i][r] = V{u[3 * bt.v[i][0] + r], u[3 * bt.v[i][1] + r], u[3 * bt.v[i][2] + r], u[3 * bt.v[i][3] + r]};
    physics::tet_deformation<Energy, S>(U, bt.Dinv, bt.vol_lambda, bt.vol_mu, d);
}

// Forces of a batch's tets scattered into f; returns their energies (with
// `Energy`, else zeros). Lanes scatter one after another, so tets of one
// batch may share vertices; scalar updates (a 4 x 4 transpose and 16 + 8
// byte updates per vertex measured 12.5 against 12.0 ns per tet on
// bunny-4k and armadillo-7k).
template <bool Energy, class S>
EDGEFEM_KERNEL typename TetBatch<S>::V batch_force(const TetBatch<S>& bt, const S* __restrict u, S* __restrict f) {
    using V = typename TetBatch<S>::V;
    BatchDeformation<S> d;
    batch_deformation<Energy>(bt, u, d);
    V Fi[4][3];
    physics::tet_forces(d, bt.Dinv, Fi);
#pragma GCC unroll 4
    for (int l = 0; l < kTetBatchLanes; ++l)
#pragma GCC unroll 4
        for (int i = 0; i < 4; ++i) {
            S* p = &f[3 * bt.v[i][l]];
            p[0] += Fi[i][0][l];
            p[1] += Fi[i][1][l];
            p[2] += Fi[i][2][l];
        }
    if constexpr (Energy) return d.energy;
    return V{};
}

// Block, row and column of each of a tet's 90 stored stiffness values.
struct TetStiffnessEntry {
    int i, j, r, c, block;
};
inline constexpr std::array<TetStiffnessEntry, 90> kTetStiffnessEntries = [] {
    std::array<TetStiffnessEntry, 90> e{};
    for (int i = 0; i < 4; ++i)
        for (int j = i; j < 4; ++j)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) {
                    const int block = tet_block_index(i, j);
                    e[9 * block + 3 * r + c] = {i, j, r, c, block};
                }
    return e;
}();

// 4 x 4 transpose: out[l] = (v0[l], v1[l], v2[l], v3[l]). In-lane unpacks,
// then 128-bit halves for 32-byte vectors (double); unpacks, then 64-bit
// halves for 16-byte ones (float).
template <class V>
EDGEFEM_KERNEL void transpose4(V v0, V v1, V v2, V v3, V (&out)[4]) {
    if constexpr (sizeof(V) == 32) {
        const V t0 = __builtin_shufflevector(v0, v1, 0, 4, 2, 6), t1 = __builtin_shufflevector(v0, v1, 1, 5, 3, 7);
        const V t2 = __builtin_shufflevector(v2, v3, 0, 4, 2, 6), t3 = __builtin_shufflevector(v2, v3, 1, 5, 3, 7);
        out[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
        out[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
        out[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
        out[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
    } else {
        const V t0 = __builtin_shufflevector(v0, v1, 0, 4, 1, 5), t1 = __builtin_shufflevector(v0, v1, 2, 6, 3, 7);
        const V t2 = __builtin_shufflevector(v2, v3, 0, 4, 1, 5), t3 = __builtin_shufflevector(v2, v3, 2, 6, 3, 7);
        out[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
        out[1] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
        out[2] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
        out[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
    }
}

// The terms of a batch's stiffness values (physics::TetStiffnessTerms, one
// tet per lane), and value e of the TetStiffness order.
template <class S>
struct BatchStiffnessTerms : physics::TetStiffnessTerms<typename TetBatch<S>::V> {
    using V = typename TetBatch<S>::V;
    EDGEFEM_KERNEL V value(int e) const {
        const TetStiffnessEntry x = kTetStiffnessEntries[e];
        return physics::tet_stiffness_entry<V>(*this, x.i, x.j, x.r, x.c);
    }
};

template <class S>
EDGEFEM_KERNEL void batch_stiffness_terms(const TetBatch<S>& bt, const BatchDeformation<S>& d, BatchStiffnessTerms<S>& k) {
    physics::tet_stiffness_terms<S>(d, bt.Dinv, bt.vol_lambda, bt.vol_mu, k);
}

// The last batch when it has padding lanes: its real lanes, value by value.
// (Recomputed from u: handing it the terms kept them in memory on the hot
// path, 40 -> 44 ns per tet on bunny-4k.)
template <class S>
__attribute__((noinline, cold)) void batch_stiffness_padded(const BatchedTetModel<S>& m, index_t b, const S* __restrict u,
                                                            S* __restrict K) {
    BatchDeformation<S> d;
    batch_deformation<false>(m.batches[b], u, d);
    BatchStiffnessTerms<S> k;
    batch_stiffness_terms(m.batches[b], d, k);
    for (int l = 0; l < kTetBatchLanes; ++l) {
        const index_t t = m.batch_tet(b, l);
        if (t >= m.num_tets()) continue;
        for (int e = 0; e < 90; ++e) K[90 * std::size_t(t) + e] = k.value(e)[l];
    }
}

// Batch b's stiffness into the per-tet layout (TetStiffness::K). The values
// are made in storage order, 4 at a time, and each 4 go out as one 4 x 4
// transpose and a vector store per tet (the last 4 at 86: 86 and 87 stored
// twice, with the same values). bench (bunny-4k, double, ns per tet): 41,
// against 48 through a 90-vector buffer and 60 with the buffer stored lane
// by lane; the batches' own layout (no transposes) would take 30.
template <class S>
EDGEFEM_KERNEL void batch_stiffness_store(const BatchedTetModel<S>& m, index_t b, const BatchStiffnessTerms<S>& k,
                                          S* __restrict K) {
    using V = typename TetBatch<S>::V;
    S* out[kTetBatchLanes];
    for (int l = 0; l < kTetBatchLanes; ++l) out[l] = &K[90 * std::size_t(m.batch_tet(b, l))];
#pragma GCC unroll 23
    for (int q = 0; q < 23; ++q) {
        const int e = q < 22 ? 4 * q : 86;
        V r[4];
        transpose4(k.value(e), k.value(e + 1), k.value(e + 2), k.value(e + 3), r);
#pragma GCC unroll 4
        for (int l = 0; l < kTetBatchLanes; ++l) std::memcpy(out[l] + e, &r[l], sizeof(V));
    }
}

template <class S>
EDGEFEM_KERNEL void batch_stiffness(const BatchedTetModel<S>& m, index_t b, const S* __restrict u, S* __restrict K) {
    if ((b + 1) * kTetBatchLanes > m.num_tets()) return batch_stiffness_padded(m, b, u, K);
    BatchDeformation<S> d;
    batch_deformation<false>(m.batches[b], u, d);
    BatchStiffnessTerms<S> k;
    batch_stiffness_terms(m.batches[b], d, k);
    batch_stiffness_store(m, b, k, K);
}

}  // namespace kernel
}  // namespace edgefem
