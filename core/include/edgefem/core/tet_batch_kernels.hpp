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

#include "edgefem/core/kernel_inline.hpp"
#include "edgefem/core/tet_model.hpp"

namespace edgefem {

namespace kernel {

// H = Du Dm^-1 and the volume-scaled S of a batch's tets.
template <class S>
struct BatchDeformation {
    using V = typename TetBatch<S>::V;
    V H[3][3];
    V Sv[3][3];
    V energy;  // Vol * (lambda/2 tr(G)^2 + mu G:G), when asked for
};

template <bool Energy, class S>
EDGEFEM_KERNEL void batch_deformation(const TetBatch<S>& bt, const S* __restrict u, BatchDeformation<S>& d) {
    using V = typename TetBatch<S>::V;
    V U[4][3];  // scalar loads into lanes: u needs no padding
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r)
            U[i][r] = V{u[3 * bt.v[i][0] + r], u[3 * bt.v[i][1] + r], u[3 * bt.v[i][2] + r], u[3 * bt.v[i][3] + r]};
    V D[3][3];  // column c: u(v_{c+1}) - u(v_0)
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) D[r][c] = U[c + 1][r] - U[0][r];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) d.H[r][c] = D[r][0] * bt.Dinv[0][c] + D[r][1] * bt.Dinv[1][c] + D[r][2] * bt.Dinv[2][c];
    const auto& H = d.H;
    V G[3][3];  // symmetric: the upper triangle computed
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
            G[j][i] = G[i][j] = S(0.5) * (H[i][j] + H[j][i] + H[0][i] * H[0][j] + H[1][i] * H[1][j] + H[2][i] * H[2][j]);
    const V tr = G[0][0] + G[1][1] + G[2][2];
    const V two_mu = 2 * bt.vol_mu, ltr = bt.vol_lambda * tr;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) d.Sv[i][j] = two_mu * G[i][j] + (i == j ? ltr : V{});
    if constexpr (Energy) {
        const V off = G[0][1] * G[0][1] + G[0][2] * G[0][2] + G[1][2] * G[1][2];
        const V GG = G[0][0] * G[0][0] + G[1][1] * G[1][1] + G[2][2] * G[2][2] + 2 * off;
        d.energy = S(0.5) * bt.vol_lambda * tr * tr + bt.vol_mu * GG;
    }
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
    V P[3][3];  // P = F S = S + H S
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            P[r][c] = d.Sv[r][c] + d.H[r][0] * d.Sv[0][c] + d.H[r][1] * d.Sv[1][c] + d.H[r][2] * d.Sv[2][c];
    V Fi[4][3];
    for (int r = 0; r < 3; ++r) {
        V sum = {};
        for (int i = 0; i < 3; ++i) {
            Fi[i + 1][r] = P[r][0] * bt.Dinv[i][0] + P[r][1] * bt.Dinv[i][1] + P[r][2] * bt.Dinv[i][2];
            sum += Fi[i + 1][r];
        }
        Fi[0][r] = -sum;
    }
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

// The terms of a batch's stiffness values, with the arithmetic of
// tet_stiffness per entry: (mu aa) FFt_rc + (lambda Fa_ir) Fa_jc +
// (mu Fa_jr) Fa_ic, + aSa on the diagonal.
template <class S>
struct BatchStiffnessTerms {
    using V = typename TetBatch<S>::V;
    V Fa[4][3], LFa[4][3], MFa[4][3], FFt[3][3], aSa[10], Maa[10];

    // Value e of the TetStiffness order, one lane per tet.
    EDGEFEM_KERNEL V value(int e) const {
        const TetStiffnessEntry x = kTetStiffnessEntries[e];
        V k = FFt[x.r][x.c] * Maa[x.block] + Fa[x.j][x.c] * LFa[x.i][x.r] + Fa[x.i][x.c] * MFa[x.j][x.r];
        if (x.r == x.c) k += aSa[x.block];
        return k;
    }
};

template <class S>
EDGEFEM_KERNEL void batch_stiffness_terms(const TetBatch<S>& bt, const BatchDeformation<S>& d, BatchStiffnessTerms<S>& k) {
    using V = typename TetBatch<S>::V;
    V F[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) F[r][c] = d.H[r][c] + (r == c ? S(1) : S(0));
    V a[4][3];  // gradients of the barycentric coordinates
    for (int c = 0; c < 3; ++c) {
        a[1][c] = bt.Dinv[0][c];
        a[2][c] = bt.Dinv[1][c];
        a[3][c] = bt.Dinv[2][c];
        a[0][c] = -(a[1][c] + a[2][c] + a[3][c]);
    }
    const V L = bt.vol_lambda, M = bt.vol_mu;
    V Sa[4][3];
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r) {
            k.Fa[i][r] = F[r][0] * a[i][0] + F[r][1] * a[i][1] + F[r][2] * a[i][2];
            Sa[i][r] = d.Sv[r][0] * a[i][0] + d.Sv[r][1] * a[i][1] + d.Sv[r][2] * a[i][2];
            k.LFa[i][r] = L * k.Fa[i][r];
            k.MFa[i][r] = M * k.Fa[i][r];
        }
    for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c) k.FFt[c][r] = k.FFt[r][c] = F[r][0] * F[c][0] + F[r][1] * F[c][1] + F[r][2] * F[c][2];
    for (int i = 0; i < 4; ++i)
        for (int j = i; j < 4; ++j) {
            k.aSa[tet_block_index(i, j)] = a[i][0] * Sa[j][0] + a[i][1] * Sa[j][1] + a[i][2] * Sa[j][2];
            k.Maa[tet_block_index(i, j)] = M * (a[i][0] * a[j][0] + a[i][1] * a[j][1] + a[i][2] * a[j][2]);
        }
}

// The last batch when it has padding lanes: its real lanes, value by value.
// (Recomputed from u: handing it the terms kept them in memory on the hot
// path, 40 -> 44 ns per tet on bunny-4k.)
template <class S>
__attribute__((noinline, cold)) void batch_stiffness_padded(const TetModel<S>& m, index_t b, const S* __restrict u,
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
EDGEFEM_KERNEL void batch_stiffness_store(const TetModel<S>& m, index_t b, const BatchStiffnessTerms<S>& k,
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
EDGEFEM_KERNEL void batch_stiffness(const TetModel<S>& m, index_t b, const S* __restrict u, S* __restrict K) {
    if ((b + 1) * kTetBatchLanes > m.num_tets()) return batch_stiffness_padded(m, b, u, K);
    BatchDeformation<S> d;
    batch_deformation<false>(m.batches[b], u, d);
    BatchStiffnessTerms<S> k;
    batch_stiffness_terms(m.batches[b], d, k);
    batch_stiffness_store(m, b, k, K);
}

}  // namespace kernel
}  // namespace edgefem
