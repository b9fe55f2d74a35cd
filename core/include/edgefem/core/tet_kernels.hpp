// Per-tet StVK kernels (Total Lagrangian): energy, nodal forces, the 12x12
// per-tet stiffness and K x. Written in the displacement-gradient form
// H = Du Dm^-1, G = (H + H^T + H^T H) / 2, which avoids the cancellation of
// (F^T F - I) / 2 at small strain, like the edge kernels' zeta.
#pragma once

#include <algorithm>
#include <type_traits>
#include <vector>

#include "edgefem/core/kernel_inline.hpp"
#include "edgefem/core/tet_batch_kernels.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/core/xyz4.hpp"

namespace edgefem {

namespace kernel {

// Deformation of one tet: F = I + H and the volume-scaled second
// Piola-Kirchhoff stress S (so P = F S is volume-scaled too).
template <class S>
struct TetDeformation {
    S F[3][3];
    S Sv[3][3];
    S energy;  // Vol * (lambda/2 tr(G)^2 + mu G:G)
};

template <class S>
EDGEFEM_KERNEL void tet_deformation(const TetModel<S>& m, index_t t, const S* __restrict u, TetDeformation<S>& out) {
    const auto& v = m.tet[t];
    const auto& d = m.data[t];
    S D[3][3];  // column c: u(v_{c+1}) - u(v_0)
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) D[r][c] = u[3 * v[c + 1] + r] - u[3 * v[0] + r];
    S H[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) H[r][c] = D[r][0] * d.Dinv[0][c] + D[r][1] * d.Dinv[1][c] + D[r][2] * d.Dinv[2][c];
    S G[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            G[i][j] = S(0.5) * (H[i][j] + H[j][i] + H[0][i] * H[0][j] + H[1][i] * H[1][j] + H[2][i] * H[2][j]);
    const S tr = G[0][0] + G[1][1] + G[2][2];
    S GG = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            out.Sv[i][j] = 2 * d.vol_mu * G[i][j] + (i == j ? d.vol_lambda * tr : S(0));
            out.F[i][j] = H[i][j] + (i == j ? S(1) : S(0));
            GG += G[i][j] * G[i][j];
        }
    out.energy = S(0.5) * d.vol_lambda * tr * tr + d.vol_mu * GG;
}

// Gradients a_0..a_3 of the tet's barycentric coordinates.
template <class S>
EDGEFEM_KERNEL void tet_grads(const TetData<S>& d, S a[4][3]) {
    for (int c = 0; c < 3; ++c) {
        a[1][c] = d.Dinv[0][c];
        a[2][c] = d.Dinv[1][c];
        a[3][c] = d.Dinv[2][c];
        a[0][c] = -(a[1][c] + a[2][c] + a[3][c]);
    }
}

// Forces of one tet scattered into f; returns its energy. (Built-in
// scalars run the batched form, tet_batch_kernels.hpp, in the loops.)
template <class S>
EDGEFEM_KERNEL S tet_force(const TetModel<S>& m, index_t t, const S* __restrict u, S* __restrict f) {
    TetDeformation<S> def;
    tet_deformation(m, t, u, def);
    S P[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            P[i][j] = def.F[i][0] * def.Sv[0][j] + def.F[i][1] * def.Sv[1][j] + def.F[i][2] * def.Sv[2][j];
    const auto& v = m.tet[t];
    const auto& d = m.data[t];
    for (int r = 0; r < 3; ++r) {
        S sum = 0;
        for (int i = 0; i < 3; ++i) {
            const S fi = P[r][0] * d.Dinv[i][0] + P[r][1] * d.Dinv[i][1] + P[r][2] * d.Dinv[i][2];
            f[3 * v[i + 1] + r] += fi;
            sum += fi;
        }
        f[3 * v[0] + r] -= sum;
    }
    return def.energy;
}

// The 10 stiffness blocks of one tet at displacement u:
// K_ab = (a_a . S a_b) I + lambda (F a_a)(F a_b)^T + mu (a_a . a_b) F F^T + mu (F a_b)(F a_a)^T
// (all volume-scaled), from dP = dF S + F dS with dS = lambda tr(dG) I + 2 mu dG.
// Per entry: (mu aa) FFt_rc + (lambda Fa_ir) Fa_jc + (mu Fa_jr) Fa_ic, + aSa
// on the diagonal. (Built-in scalars run the batched form in the loops.)
template <class S>
EDGEFEM_KERNEL void tet_stiffness(const TetModel<S>& m, index_t t, const S* __restrict u, S* __restrict Kt) {
    TetDeformation<S> def;
    tet_deformation(m, t, u, def);
    const auto& d = m.data[t];
    S a[4][3];
    tet_grads(d, a);
    // Material constants without the volume: Sv already carries it, and
    // vol_lambda / vol_mu carry it for the other terms.
    const S L = d.vol_lambda, M = d.vol_mu;
    S Fa[4][3], Sa[4][3], FFt[3][3];
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r) {
            Fa[i][r] = def.F[r][0] * a[i][0] + def.F[r][1] * a[i][1] + def.F[r][2] * a[i][2];
            Sa[i][r] = def.Sv[r][0] * a[i][0] + def.Sv[r][1] * a[i][1] + def.Sv[r][2] * a[i][2];
        }
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            FFt[r][c] = def.F[r][0] * def.F[c][0] + def.F[r][1] * def.F[c][1] + def.F[r][2] * def.F[c][2];
    for (int i = 0; i < 4; ++i)
        for (int j = i; j < 4; ++j) {
            const S aSa = a[i][0] * Sa[j][0] + a[i][1] * Sa[j][1] + a[i][2] * Sa[j][2];
            const S Maa = M * (a[i][0] * a[j][0] + a[i][1] * a[j][1] + a[i][2] * a[j][2]);
            S* blk = &Kt[9 * tet_block_index(i, j)];
            for (int r = 0; r < 3; ++r) {
                const S LFa = L * Fa[i][r], MFa = M * Fa[j][r];
                for (int c = 0; c < 3; ++c) blk[3 * r + c] = FFt[r][c] * Maa + Fa[j][c] * LFa + Fa[i][c] * MFa;
                blk[3 * r + r] += aSa;
            }
        }
}

// y += K_t x for one tet from its stored blocks. Built-in scalars: each
// block row a 4-lane vector; K_ab x_b as lane-wise products summed across
// the lanes once per vertex, K_ba x_a = K_ab^T x_a as broadcast FMAs (lane
// 3 of a row holds the next stored value and is never read back).
template <class S>
EDGEFEM_KERNEL void tet_kx(const TetModel<S>& m, index_t t, const S* __restrict Kt, const S* __restrict x, S* __restrict y) {
    const auto& v = m.tet[t];
    if constexpr (std::is_floating_point_v<S>) {
        using X = Xyz4<S>;
        using V = typename X::V;
        V xv[4], col[4] = {}, rw[4][3] = {};
        for (int i = 0; i < 4; ++i) xv[i] = X::load(&x[3 * v[i]]);
#pragma GCC unroll 4
        for (int i = 0; i < 4; ++i)
#pragma GCC unroll 4
            for (int j = i; j < 4; ++j) {
                const S* blk = &Kt[9 * tet_block_index(i, j)];
                // The tet's last row: 3 loads (lane 3 would be the next tet's).
                const V k0 = X::row(blk), k1 = X::row(blk + 3), k2 = i == 3 ? X::load(blk + 6) : X::row(blk + 6);
                rw[i][0] += k0 * xv[j];
                rw[i][1] += k1 * xv[j];
                rw[i][2] += k2 * xv[j];
                if (j != i) col[j] += k0 * xv[i][0] + k1 * xv[i][1] + k2 * xv[i][2];
            }
        for (int i = 0; i < 4; ++i)
            for (int r = 0; r < 3; ++r) y[3 * v[i] + r] += col[i][r] + (rw[i][r][0] + rw[i][r][1] + rw[i][r][2]);
    } else {
        for (int i = 0; i < 4; ++i) {
            S acc[3] = {0, 0, 0};
            for (int j = 0; j < 4; ++j) {
                const S* xj = &x[3 * v[j]];
                if (i <= j) {
                    const S* blk = &Kt[9 * tet_block_index(i, j)];
                    for (int r = 0; r < 3; ++r) acc[r] += blk[3 * r] * xj[0] + blk[3 * r + 1] * xj[1] + blk[3 * r + 2] * xj[2];
                } else {
                    const S* blk = &Kt[9 * tet_block_index(j, i)];
                    for (int r = 0; r < 3; ++r) acc[r] += blk[r] * xj[0] + blk[3 + r] * xj[1] + blk[6 + r] * xj[2];
                }
            }
            for (int r = 0; r < 3; ++r) y[3 * v[i] + r] += acc[r];
        }
    }
}

// y += K_t(u) x for one tet without stored blocks: dF = dDx Dm^-1,
// dP = dF S + F dS, y_i += dP a_i.
template <class S>
EDGEFEM_KERNEL void tet_kx_matrix_free(const TetModel<S>& m, index_t t, const S* __restrict u, const S* __restrict x,
                               S* __restrict y) {
    TetDeformation<S> def;
    tet_deformation(m, t, u, def);
    const auto& v = m.tet[t];
    const auto& d = m.data[t];
    S dD[3][3], dF[3][3];
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) dD[r][c] = x[3 * v[c + 1] + r] - x[3 * v[0] + r];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) dF[r][c] = dD[r][0] * d.Dinv[0][c] + dD[r][1] * d.Dinv[1][c] + dD[r][2] * d.Dinv[2][c];
    S dG[3][3];  // sym(F^T dF)
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            S s = 0;
            for (int k = 0; k < 3; ++k) s += def.F[k][i] * dF[k][j] + dF[k][i] * def.F[k][j];
            dG[i][j] = S(0.5) * s;
        }
    const S tr = dG[0][0] + dG[1][1] + dG[2][2];
    S dS[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) dS[i][j] = 2 * d.vol_mu * dG[i][j] + (i == j ? d.vol_lambda * tr : S(0));
    S dP[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            S s = 0;
            for (int k = 0; k < 3; ++k) s += dF[i][k] * def.Sv[k][j] + def.F[i][k] * dS[k][j];
            dP[i][j] = s;
        }
    for (int r = 0; r < 3; ++r) {
        S sum = 0;
        for (int i = 0; i < 3; ++i) {
            const S yi = dP[r][0] * d.Dinv[i][0] + dP[r][1] * d.Dinv[i][1] + dP[r][2] * d.Dinv[i][2];
            y[3 * v[i + 1] + r] += yi;
            sum += yi;
        }
        y[3 * v[0] + r] -= sum;
    }
}

}  // namespace kernel

// ---- Serial loops -------------------------------------------------------

// f = dW/du (overwritten); returns W when `Energy`, else 0. Built-in
// scalars run the batches (TetModel::batches), the energy summed batch by
// batch, lane by lane.
template <bool Energy, class S>
double tet_forces(const TetModel<S>& m, const S* u, S* f) {
    std::fill(f, f + 3 * std::size_t(m.num_vertices), S(0));
    double W = 0;
    if constexpr (std::is_floating_point_v<S>) {
        for (const TetBatch<S>& bt : m.batches) {
            const auto w = kernel::batch_force<Energy>(bt, u, f);
            if constexpr (Energy)
                for (int l = 0; l < kTetBatchLanes; ++l) W += double(w[l]);
        }
    } else {
        for (index_t t = 0; t < m.num_tets(); ++t) {
            const S w = kernel::tet_force(m, t, u, f);
            if constexpr (Energy) W += double(w);
        }
    }
    return W;
}

// Per-tet energies (#T), e.g. for output as energy density.
template <class S>
void tet_energies(const TetModel<S>& m, const S* u, double* energy) {
    kernel::TetDeformation<S> def;
    for (index_t t = 0; t < m.num_tets(); ++t) {
        kernel::tet_deformation(m, t, u, def);
        energy[t] = double(def.energy);
    }
}

template <class S>
void tet_stiffness_all(const TetModel<S>& m, const S* u, TetStiffness<S>& K) {
    K.K.resize(90 * std::size_t(m.num_tets()));
    if constexpr (std::is_floating_point_v<S>) {
        for (index_t b = 0; b < m.num_batches(); ++b) kernel::batch_stiffness(m, b, u, K.K.data());
    } else {
        for (index_t t = 0; t < m.num_tets(); ++t) kernel::tet_stiffness(m, t, u, &K.K[90 * std::size_t(t)]);
    }
}

// Conventional F+K: forces and the 12x12 stiffness of every tet. (One
// deformation per batch for both, fused, measured no faster: 51 against
// 51-53 ns per tet on bunny-4k, 52-53 both on armadillo-7k.)
template <bool Energy, class S>
double tet_forces_stiffness(const TetModel<S>& m, const S* u, S* f, TetStiffness<S>& K) {
    const double W = tet_forces<Energy>(m, u, f);
    tet_stiffness_all(m, u, K);
    return W;
}

// y = K x from stored per-tet blocks (overwritten).
template <class S>
void tet_multiply(const TetModel<S>& m, const TetStiffness<S>& K, const S* x, S* y) {
    std::fill(y, y + 3 * std::size_t(m.num_vertices), S(0));
    for (index_t t = 0; t < m.num_tets(); ++t) kernel::tet_kx(m, t, &K.K[90 * std::size_t(t)], x, y);
}

// y = K(u) x recomputing each tet's deformation (overwritten).
template <class S>
void tet_multiply_matrix_free(const TetModel<S>& m, const S* u, const S* x, S* y) {
    std::fill(y, y + 3 * std::size_t(m.num_vertices), S(0));
    for (index_t t = 0; t < m.num_tets(); ++t) kernel::tet_kx_matrix_free(m, t, u, x, y);
}

}  // namespace edgefem
