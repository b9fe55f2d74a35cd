// The edge term of the per-edge tangent stiffness (docs/formulation.md
// section 5): K(E) = -g(E) I - 2 L(E) p~ p~^T, the block K[V0, V1] before
// the TSEP terms are added (for the spring network, the whole block).
//
// `definite` uses max(g, 0) in place of g: the Hessian is J^T A J (positive
// semi-definite) plus the edge Laplacian weighted by g, so only edges with
// g < 0 can make K indefinite; clamping them leaves K positive
// semi-definite and the forces unchanged.
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

// g as the stiffness uses it (clamped at zero when `definite`).
EDGEFEM_FORMULA double stiffness_g(double g, bool definite) { return definite && g < 0.0 ? 0.0 : g; }

// K(E) from p~ = q, L(E) and g in the kernels' scalar, row-major,
// overwriting k[0..8].
template <class T>
EDGEFEM_FORMULA void edge_stiffness(T LE, T g, const T* q, T* k) {
    const T c = -2 * LE;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) k[3 * i + j] = c * q[i] * q[j] - (i == j ? g : T(0));
}

}  // namespace edgefem::physics
