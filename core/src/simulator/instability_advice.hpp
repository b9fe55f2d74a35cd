// What an unstable step's error message advises, by integrator: the remedy
// that exists for it (docs/dynamics.md, "Which integrator to pick").
#pragma once

#include <string>

#include "edgefem/core/scene.hpp"

namespace edgefem::sim {

inline std::string instability_advice(Integrator i) {
    switch (i) {
        case Integrator::Explicit:
        case Integrator::Verlet:
            return "unstable: reduce dt, use an implicit integrator or improve the mesh's worst tets";
        case Integrator::Newmark:
        case Integrator::NewmarkLinear:  // no numerical damping: the trapezoidal rule on a stiff nonlinear body
            return "unstable: reduce dt, use bdf2 or generalized-alpha (numerical damping) or improve the mesh's "
                   "worst tets";
        case Integrator::GeneralizedAlpha:
        case Integrator::GeneralizedAlphaLinear:  // a nearly incompressible body at the default rho_inf 0.8
            return "unstable: reduce dt, lower generalized_alpha.rho_inf (0.6 or less), use bdf2 or improve the "
                   "mesh's worst tets";
        default:
            return "unstable: reduce dt or improve the mesh's worst tets";
    }
}

}  // namespace edgefem::sim
