// Per-tet StVK kernels (Total Lagrangian): energy, nodal forces, the 12x12
// per-tet stiffness and K x. Written in the displacement-gradient form
// H = Du Dm^-1, G = (H + H^T + H^T H) / 2, which avoids the cancellation of
// (F^T F - I) / 2 at small strain, like the edge kernels' zeta.
#pragma once

#include <algorithm>
#include <type_traits>
#include <vector>

#include "cpu/kernel_inline.hpp"
#include "cpu/tet_batch_kernels.hpp"
#include "edgefem/core/tet_model.hpp"
#include "cpu/xyz4.hpp"
#include "edgefem/physics/edge_blocks.hpp"
#include "edgefem/physics/tet_stvk.hpp"

namespace edgefem {

namespace kernel {

// The displacements of tet t's vertices, as the per-tet formulas take them.
template <class S>
EDGEFEM_KERNEL void tet_displacements(const TetModel<S>& m, index_t t, const S* __restrict u, S (&U)[4][3]) {
    const auto& v = m.tet[t];
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r) U[i][r] = u[3 * v[i] + r];
}

// The deformation of tet t at displacement u (physics::tet_deformation).
template <bool Energy, class S>
EDGEFEM_KERNEL physics::TetDeformation<S> tet_deformation(const TetModel<S>& m, index_t t, const S* __restrict u) {
    S U[4][3];
    tet_displacements(m, t, u, U);
    const auto& d = m.data[t];
    physics::TetDeformation<S> def;
    physics::tet_deformation<Energy, S>(U, d.Dinv, d.vol_lambda, d.vol_mu, def);
    return def;
}

// y[v_i] += dy[i] for tet t's vertices.
template <class S>
EDGEFEM_KERNEL void tet_scatter(const TetModel<S>& m, index_t t, const S (&dy)[4][3], S* __restrict y) {
    const auto& v = m.tet[t];
    for (int i = 0; i < 4; ++i)
        for (int r = 0; r < 3; ++r) y[3 * v[i] + r] += dy[i][r];
}

// Forces of one tet scattered into f; returns its energy. (Built-in
// scalars run the batched form, tet_batch_kernels.hpp, in the loops.)
template <class S>
EDGEFEM_KERNEL S tet_force(const TetModel<S>& m, index_t t, const S* __restrict u, S* __restrict f) {
    const physics::TetDeformation<S> def = tet_deformation<true>(m, t, u);
    S fi[4][3];
    physics::tet_forces(def, m.data[t].Dinv, fi);
    tet_scatter(m, t, fi, f);
    return def.energy;
}

// The 10 stiffness blocks of one tet at displacement u (physics::
// tet_stiffness_entry). (Built-in scalars run the batched form in the loops.)
template <class S>
EDGEFEM_KERNEL void tet_stiffness(const TetModel<S>& m, index_t t, const S* __restrict u, S* __restrict Kt) {
    const physics::TetDeformation<S> def = tet_deformation<false>(m, t, u);
    const auto& d = m.data[t];
    physics::TetStiffnessTerms<S> k;
    physics::tet_stiffness_terms<S>(def, d.Dinv, d.vol_lambda, d.vol_mu, k);
    physics::tet_stiffness_blocks(k, Kt);
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
                rw[i][0] += physics::row_products(k0, xv[j]);
                rw[i][1] += physics::row_products(k1, xv[j]);
                rw[i][2] += physics::row_products(k2, xv[j]);
                if (j != i) col[j] += physics::transpose_times(k0, k1, k2, xv[i][0], xv[i][1], xv[i][2]);
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
                    for (int r = 0; r < 3; ++r) acc[r] += physics::row_times(blk[3 * r], blk[3 * r + 1], blk[3 * r + 2], xj[0], xj[1], xj[2]);
                } else {
                    const S* blk = &Kt[9 * tet_block_index(j, i)];
                    for (int r = 0; r < 3; ++r) acc[r] += physics::transpose_times(blk[r], blk[3 + r], blk[6 + r], xj[0], xj[1], xj[2]);
                }
            }
            for (int r = 0; r < 3; ++r) y[3 * v[i] + r] += acc[r];
        }
    }
}

// y += K_t(u) x for one tet without stored blocks
// (physics::tet_stiffness_times).
template <class S>
EDGEFEM_KERNEL void tet_kx_matrix_free(const TetModel<S>& m, index_t t, const S* __restrict u, const S* __restrict x,
                               S* __restrict y) {
    const physics::TetDeformation<S> def = tet_deformation<false>(m, t, u);
    const auto& d = m.data[t];
    S X[4][3], dy[4][3];
    tet_displacements(m, t, x, X);
    physics::tet_stiffness_times<S>(def, X, d.Dinv, d.vol_lambda, d.vol_mu, dy);
    tet_scatter(m, t, dy, y);
}

}  // namespace kernel

// ---- Serial loops -------------------------------------------------------

// f = dW/du (overwritten); returns W when `Energy`, else 0. Built-in
// scalars run the batches (BatchedTetModel::batches), the energy summed batch by
// batch, lane by lane.
template <bool Energy, class S>
double tet_forces(const BatchedTetModel<S>& m, const S* u, S* f) {
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
    for (index_t t = 0; t < m.num_tets(); ++t) energy[t] = double(kernel::tet_deformation<true>(m, t, u).energy);
}

template <class S>
void tet_stiffness_all(const BatchedTetModel<S>& m, const S* u, TetStiffness<S>& K) {
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
double tet_forces_stiffness(const BatchedTetModel<S>& m, const S* u, S* f, TetStiffness<S>& K) {
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
