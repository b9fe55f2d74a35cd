// The TSEP term of the per-edge tangent stiffness (docs/formulation.md
// section 5): pair P of edges E0, E1 contributes
//
//   Kp(P) = 2 L(P) p~(E0) p~(E1)^T
//
// with sign (-1)^(i+j) to the block of the edge E2 joining end i of E0 and
// end j of E1 (slot k = 2 i + j of the pair's four targets), transposed
// where E2 runs the other way, and nowhere when the two ends coincide (a
// diagonal block). A transposed target takes x = p~(E1), y = p~(E0).
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

// 2 L(P), and its sign for slot k: + for k = 0, 3, - for 1, 2.
template <class T>
EDGEFEM_FORMULA T pair_coefficient(T LP) {
    return 2 * LP;
}
template <class T>
EDGEFEM_FORMULA T slot_coefficient(T c, int k) {
    return (k == 0 || k == 3) ? c : -c;
}

// Row i of the contribution: blk(i, j) += (c x_i) y_j, j = 0..2.
template <class T>
EDGEFEM_FORMULA void add_pair_block_row(T c, T xi, T y0, T y1, T y2, T* row) {
    const T s = c * xi;
    row[0] += s * y0;
    row[1] += s * y1;
    row[2] += s * y2;
}

// The whole contribution, added to the row-major block blk.
template <class T>
EDGEFEM_FORMULA void add_pair_block(T c, const T* x, const T* y, T* blk) {
    const T y0 = y[0], y1 = y[1], y2 = y[2];
    for (int i = 0; i < 3; ++i) add_pair_block_row(c, x[i], y0, y1, y2, blk + 3 * i);
}

}  // namespace edgefem::physics
