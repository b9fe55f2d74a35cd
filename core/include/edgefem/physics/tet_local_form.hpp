// The edge-based forces and stiffness tet by tet: the tet-local form
// (docs/formulation.md section 5, "The same K from the tet-local form").
// Per tet, W_T = 1/4 sum_{k,l} A_kl(T) zeta_k zeta_l over its 6 local edges
// (tet_local.hpp's numbering, vertices in ascending global order so that
// every local edge runs as its global edge does). Its diagonal A_kk sums
// into L(E) and stays with the edges (edge_g.hpp, edge_stiffness.hpp); the
// off-diagonal A_kl give, per tet,
//
//   g(E_k) += sum_{l != k} A_kl zeta_l                       (pair_g terms)
//   K_ab   = 2 sum_{k ni a} sum_{l ni b} s_ka s_lb A_kl p~_k p~_l^T
//          = 2 sum_{k ni a} s_ka p~_k W_kb^T,  W_kb = sum_{l ni b} s_lb A_kl p~_l
//
// the off-diagonal block of local edge (a, b), which summed over tets (with
// the edge term) is the per-edge K(E): the TSEP terms of tsep_stiffness.hpp
// grouped by tet.
//
// T: a scalar or a SIMD lane type with one tet per lane; S its scalar (for
// the constant factors). `coef(k, l)` returns A_kl for k != l (a T), and
// zero for k == l.
#pragma once

#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/host_device.hpp"
#include "edgefem/physics/tet_local.hpp"

namespace edgefem::physics {

// The tet's pair terms of g(E_k): sum_{l != k} A_kl zeta_l, l ascending.
template <class T, class Coef>
EDGEFEM_FORMULA T form_g(int k, const Coef& coef, const T (&zeta)[6]) {
    T s = {};
    EDGEFEM_UNROLL(6)
    for (int l = 0; l < 6; ++l) {
        if (l == k) continue;  // the diagonal stays with the edges (L(E))
        s += pair_g(coef(k, l), zeta[l]);
    }
    return s;
}

// W[k][v][c] = sum over the 3 edges m at vertex v of s_mv A_km p~_m[c].
template <class S, class T, class Coef>
EDGEFEM_FORMULA void form_w(const Coef& coef, const T (&p)[6][3], T (&W)[6][4][3]) {
    EDGEFEM_UNROLL(6)
    for (int k = 0; k < 6; ++k)
        EDGEFEM_UNROLL(4)
        for (int v = 0; v < 4; ++v) {
            const int m0 = vertex_edge(v, 0), m1 = vertex_edge(v, 1), m2 = vertex_edge(v, 2);
            const T a0 = S(vertex_sign(v, 0)) * coef(k, m0), a1 = S(vertex_sign(v, 1)) * coef(k, m1),
                    a2 = S(vertex_sign(v, 2)) * coef(k, m2);
            for (int c = 0; c < 3; ++c) W[k][v][c] = a0 * p[m0][c] + a1 * p[m1][c] + a2 * p[m2][c];
        }
}

// K_ab of local edge e = (a, b), row-major into kv: 2 sum over the edges k
// at a of s_ka p~_k W[k][b]^T.
template <class S, class T>
EDGEFEM_FORMULA void form_block(int e, const T (&p)[6][3], const T (&W)[6][4][3], T (&kv)[9]) {
    const int a = tet_edge_vertex(e, 0), b = tet_edge_vertex(e, 1);
    const int k0 = vertex_edge(a, 0), k1 = vertex_edge(a, 1), k2 = vertex_edge(a, 2);
    const S s0 = S(2 * vertex_sign(a, 0)), s1 = S(2 * vertex_sign(a, 1)), s2 = S(2 * vertex_sign(a, 2));
    for (int i = 0; i < 3; ++i) {
        const T x0 = s0 * p[k0][i], x1 = s1 * p[k1][i], x2 = s2 * p[k2][i];
        for (int j = 0; j < 3; ++j) kv[3 * i + j] = x0 * W[k0][b][j] + x1 * W[k1][b][j] + x2 * W[k2][b][j];
    }
}

}  // namespace edgefem::physics
