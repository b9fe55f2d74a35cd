// The per-tet Total Lagrangian StVK element (docs/formulation.md section 8),
// the reference and baseline of the edge-based method, in the
// displacement-gradient form that avoids the cancellation of (F^T F - I) / 2
// at small strain (section 6):
//
//   H = Du Dm^-1,  F = I + H,  G = (H + H^T + H^T H) / 2,
//   S = 2 mu G + lambda tr(G) I,  W = Vol (lambda/2 tr(G)^2 + mu G:G),
//   P = F S = S + H S,  f_i = P a_i (i = 1..3),  f_0 = -(f_1 + f_2 + f_3),
//   K_ab = (a_a . S a_b) I + lambda (F a_a)(F a_b)^T + mu (a_a . a_b) F F^T
//          + mu (F a_b)(F a_a)^T,
//   dP = dF S + F dS,  dS = lambda tr(dG) I + 2 mu dG,  dG = sym(F^T dF)
//
// with the material constants premultiplied by the rest volume (so S, P, f
// and K are volume-scaled), and a_i the gradients of the barycentric
// coordinates (rows of Dm^-1 for i = 1..3, a_0 = -(a_1 + a_2 + a_3)).
//
// T: a scalar, or a SIMD lane type with one tet per lane; S its scalar (for
// constants). Inputs and outputs are small arrays; no loop over tets.
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

// The deformation of one tet: H and the volume-scaled S; the energy when
// asked for.
template <class T>
struct TetDeformation {
    T H[3][3];
    T Sv[3][3];
    T energy;
};

// H = Du Dm^-1 from the displacements U[i] of the tet's vertices and Dm^-1
// (rows grad phi_1..3).
template <class T>
EDGEFEM_FORMULA void displacement_gradient(const T (&U)[4][3], const T (&Dinv)[3][3], T (&H)[3][3]) {
    T D[3][3];  // column c: u(v_{c+1}) - u(v_0)
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) D[r][c] = U[c + 1][r] - U[0][r];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) H[r][c] = D[r][0] * Dinv[0][c] + D[r][1] * Dinv[1][c] + D[r][2] * Dinv[2][c];
}

// The Green strain G = (F^T F - I) / 2 = (H + H^T + H^T H) / 2 (symmetric).
template <class S, class T>
EDGEFEM_FORMULA void green_strain(const T (&H)[3][3], T (&G)[3][3]) {
    for (int i = 0; i < 3; ++i)  // the upper triangle computed
        for (int j = i; j < 3; ++j)
            G[j][i] = G[i][j] = S(0.5) * (H[i][j] + H[j][i] + H[0][i] * H[0][j] + H[1][i] * H[1][j] + H[2][i] * H[2][j]);
}

// The StVK second Piola-Kirchhoff stress S = 2 mu G + lambda tr(G) I
// (volume-scaled when lambda and mu are); returns tr(G), which the energy
// needs too.
template <class T>
EDGEFEM_FORMULA T stvk_stress(const T (&G)[3][3], T lambda, T mu, T (&Sv)[3][3]) {
    const T tr = G[0][0] + G[1][1] + G[2][2];
    const T two_mu = 2 * mu, ltr = lambda * tr;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Sv[i][j] = two_mu * G[i][j] + (i == j ? ltr : T{});
    return tr;
}

// From the displacements U[i] of the tet's vertices and Dm^-1 (rows
// grad phi_1..3), with vol_lambda = Vol lambda, vol_mu = Vol mu.
template <bool Energy, class S, class T>
EDGEFEM_FORMULA void tet_deformation(const T (&U)[4][3], const T (&Dinv)[3][3], T vol_lambda, T vol_mu,
                                     TetDeformation<T>& d) {
    displacement_gradient(U, Dinv, d.H);
    T G[3][3];
    green_strain<S>(d.H, G);
    [[maybe_unused]] const T tr = stvk_stress(G, vol_lambda, vol_mu, d.Sv);
    if constexpr (Energy) {
        const T off = G[0][1] * G[0][1] + G[0][2] * G[0][2] + G[1][2] * G[1][2];
        const T GG = G[0][0] * G[0][0] + G[1][1] * G[1][1] + G[2][2] * G[2][2] + 2 * off;
        d.energy = S(0.5) * vol_lambda * tr * tr + vol_mu * GG;
    }
}

// The nodal vectors of a (volume-scaled) first Piola-Kirchhoff stress P:
// f_i = P a_i for i = 1..3 and f_0 = -(f_1 + f_2 + f_3).
template <class T>
EDGEFEM_FORMULA void nodal_vectors(const T (&P)[3][3], const T (&Dinv)[3][3], T (&f)[4][3]) {
    for (int r = 0; r < 3; ++r) {
        T sum = {};
        for (int i = 0; i < 3; ++i) {
            f[i + 1][r] = P[r][0] * Dinv[i][0] + P[r][1] * Dinv[i][1] + P[r][2] * Dinv[i][2];
            sum += f[i + 1][r];
        }
        f[0][r] = -sum;
    }
}

// The nodal forces f[i] (the energy gradient) of the tet: P = S + H S, then
// its nodal vectors.
template <class T>
EDGEFEM_FORMULA void tet_forces(const TetDeformation<T>& d, const T (&Dinv)[3][3], T (&f)[4][3]) {
    T P[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            P[r][c] = d.Sv[r][c] + d.H[r][0] * d.Sv[0][c] + d.H[r][1] * d.Sv[1][c] + d.H[r][2] * d.Sv[2][c];
    nodal_vectors(P, Dinv, f);
}

// The gradients a_0..a_3 of the barycentric coordinates.
template <class T>
EDGEFEM_FORMULA void barycentric_gradients(const T (&Dinv)[3][3], T (&a)[4][3]) {
    for (int c = 0; c < 3; ++c) {
        a[1][c] = Dinv[0][c];
        a[2][c] = Dinv[1][c];
        a[3][c] = Dinv[2][c];
        a[0][c] = -(a[1][c] + a[2][c] + a[3][c]);
    }
}

// Block a <= b of the 10 distinct 3x3 blocks of a tet's 12 x 12 stiffness,
// in the order (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3) (2,2) (2,3) (3,3).
EDGEFEM_HOST_DEVICE constexpr int tet_block_index(int a, int b) {
    constexpr int start[4] = {0, 4, 7, 9};
    return start[a] + (b - a);
}

// What the stiffness blocks are made of: F a_i, lambda F a_i, mu F a_i, F F^T,
// a_i . S a_j and mu a_i . a_j (blocks i <= j).
template <class T>
struct TetStiffnessTerms {
    T Fa[4][3], LFa[4][3], MFa[4][3], FFt[3][3], aSa[10], Maa[10];
};

template <class S, class T>
EDGEFEM_FORMULA void tet_stiffness_terms(const TetDeformation<T>& d, const T (&Dinv)[3][3], T vol_lambda, T vol_mu,
                                         TetStiffnessTerms<T>& k) {
    T F[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) F[r][c] = d.H[r][c] + (r == c ? S(1) : S(0));
    T a[4][3];
    barycentric_gradients(Dinv, a);
    const T L = vol_lambda, M = vol_mu;
    T Sa[4][3];
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

// Entry (r, c) of block (i, j), i <= j: (mu aa) FFt_rc + (lambda Fa_ir) Fa_jc
// + (mu Fa_jr) Fa_ic, + a_i . S a_j on the diagonal.
template <class T>
EDGEFEM_FORMULA T tet_stiffness_entry(const TetStiffnessTerms<T>& k, int i, int j, int r, int c) {
    const int block = tet_block_index(i, j);
    T v = k.FFt[r][c] * k.Maa[block] + k.Fa[j][c] * k.LFa[i][r] + k.Fa[i][c] * k.MFa[j][r];
    if (r == c) v += k.aSa[block];
    return v;
}

// The 10 distinct blocks (i <= j, tet_block_index order, each row-major)
// into Kt[0..89].
template <class T>
EDGEFEM_FORMULA void tet_stiffness_blocks(const TetStiffnessTerms<T>& k, T* Kt) {
    for (int i = 0; i < 4; ++i)
        for (int j = i; j < 4; ++j)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) Kt[9 * tet_block_index(i, j) + 3 * r + c] = tet_stiffness_entry(k, i, j, r, c);
}

// The K x of one tet without stored blocks, for a direction x given per
// vertex (X): dF = dX Dm^-1, dP = dF S + F dS, dy = the nodal vectors of dP
// (overwritten).
template <class S, class T>
EDGEFEM_FORMULA void tet_stiffness_times(const TetDeformation<T>& d, const T (&X)[4][3], const T (&Dinv)[3][3],
                                         T vol_lambda, T vol_mu, T (&dy)[4][3]) {
    T F[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) F[r][c] = d.H[r][c] + (r == c ? S(1) : S(0));
    T dD[3][3], dF[3][3];
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) dD[r][c] = X[c + 1][r] - X[0][r];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) dF[r][c] = dD[r][0] * Dinv[0][c] + dD[r][1] * Dinv[1][c] + dD[r][2] * Dinv[2][c];
    T dG[3][3];  // sym(F^T dF)
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            T s = {};
            for (int k = 0; k < 3; ++k) s += F[k][i] * dF[k][j] + dF[k][i] * F[k][j];
            dG[i][j] = S(0.5) * s;
        }
    const T tr = dG[0][0] + dG[1][1] + dG[2][2];
    T dS[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) dS[i][j] = 2 * vol_mu * dG[i][j] + (i == j ? vol_lambda * tr : T{});
    T dP[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            T s = {};
            for (int k = 0; k < 3; ++k) s += dF[i][k] * d.Sv[k][j] + F[i][k] * dS[k][j];
            dP[i][j] = s;
        }
    nodal_vectors(dP, Dinv, dy);
}

}  // namespace edgefem::physics
