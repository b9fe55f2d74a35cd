// The strain of one edge (docs/formulation.md sections 1 and 6): its
// current vector p~ = x(V0) - x(V1) and zeta = |p~|^2 - H, the change of its
// squared length, computed from the displacement without cancellation.
//
// Inputs: d = u(V0) - u(V1), the difference of the end displacements
// (u = x - X); r = X(V0) - X(V1), the rest edge vector (|r|^2 = H).
// Outputs: p~ = r + d in q; returns zeta = d . (r + p~), which equals
// |p~|^2 - |r|^2 but keeps its digits at small strain (at strain 1e-4 the
// naive difference keeps none in float).
//
// T: a scalar, or a SIMD lane type with one edge per lane; no loop, no
// memory access: every back-end (reference loops, CPU lanes, GPU threads)
// calls this.
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

template <class T>
EDGEFEM_FORMULA T edge_strain(T d0, T d1, T d2, T r0, T r1, T r2, T& q0, T& q1, T& q2) {
    q0 = r0 + d0;
    q1 = r1 + d1;
    q2 = r2 + d2;
    return d0 * (r0 + q0) + d1 * (r1 + q1) + d2 * (r2 + q2);
}

}  // namespace edgefem::physics
