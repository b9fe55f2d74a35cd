// The nodal force of one edge (docs/formulation.md section 4): the energy
// gradient f = dW/du gets p~(E) g(E) at V0 and -p~(E) g(E) at V1.
//
// Inputs: one component of p~(E), and g(E) in the kernels' scalar.
// Returns the component added to f(V0) (and subtracted from f(V1)).
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

template <class T>
EDGEFEM_FORMULA T edge_force(T p, T g) {
    return p * g;
}

}  // namespace edgefem::physics
