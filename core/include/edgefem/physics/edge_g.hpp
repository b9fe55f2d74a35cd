// The per-edge coefficient g(E) of the forces and the energy
// (docs/formulation.md sections 3, 4 and 7):
//
//   g(E) = L(E) zeta(E) + sum over the TSEPs P containing E of L(P) zeta(F),
//   F the other edge of P;   W = 1/4 sum_E zeta(E) g(E).
//
// The spring network (SN) is the first term alone. The TSEP terms are summed
// in double whatever the kernels' scalar (section 6: they cancel heavily on
// graded meshes). The tet-local form sums the same pair terms tet by tet
// with A_EF(T) in place of L(P) (section 5); their sum over tets is L(P).
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

// L(E) zeta(E): the edge's own term of g(E).
template <class T>
EDGEFEM_FORMULA T own_g(T LE, T zeta) {
    return LE * zeta;
}

// L(P) zeta(F): the term pair P adds to g(E), F its other edge (both ways:
// g(E0) gets L(P) zeta(E1), g(E1) gets L(P) zeta(E0)).
template <class T>
EDGEFEM_FORMULA T pair_g(T LP, T zeta_other) {
    return LP * zeta_other;
}

// One edge's term of 4 W, and W from the sum of those terms.
EDGEFEM_FORMULA double energy_term(double zeta, double g) { return zeta * g; }
EDGEFEM_FORMULA double energy_from_terms(double sum) { return 0.25 * sum; }

}  // namespace edgefem::physics
