// What the per-edge blocks K(E) = K[V0, V1] give (docs/formulation.md
// section 5), with d = x(V0) - x(V1):
//
//   K x:              y(V0) -= K(E) d,  y(V1) += K(E)^T d;
//   diagonal blocks:  K[V0, V0] -= K(E), K[V1, V1] -= K(E)^T
//                     (translation invariance: the rows of K sum to zero).
//
// K(E) is row-major. A row or column may be passed as a scalar per entry or
// as a SIMD vector of the row's three entries (R); the CPU back-end's lane
// kernel forms K(E) d lane-wise (row_products) and adds the lanes once per
// vertex.
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

// (K(E) d)_i from row i of K(E).
template <class T>
EDGEFEM_FORMULA T row_times(T k0, T k1, T k2, T d0, T d1, T d2) {
    return k0 * d0 + k1 * d1 + k2 * d2;
}

// The products k_ij d_j of a row held as a vector (R), whose lanes summed
// are (K(E) d)_i.
template <class R>
EDGEFEM_FORMULA R row_products(R row, R d) {
    return row * d;
}

// K(E)^T d: the rows of K(E) weighted by the entries of d. With the rows as
// vectors (R), all of K^T d at once; with scalars, column j from the j-th
// entries of the rows.
template <class R, class T>
EDGEFEM_FORMULA R transpose_times(R row0, R row1, R row2, T d0, T d1, T d2) {
    return d0 * row0 + d1 * row1 + d2 * row2;
}

// The diagonal blocks' terms of edge E: D(V0) -= K(E), D(V1) -= K(E)^T.
template <class T>
EDGEFEM_FORMULA void subtract_block(const T* k, T* d0) {
    for (int q = 0; q < 9; ++q) d0[q] -= k[q];
}
template <class T>
EDGEFEM_FORMULA void subtract_block_transposed(const T* k, T* d1) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) d1[3 * i + j] -= k[3 * j + i];
}

}  // namespace edgefem::physics
