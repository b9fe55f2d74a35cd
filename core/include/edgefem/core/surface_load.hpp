// The nodal forces of a surface load (SurfaceLoad, scene.hpp): pressure and
// traction on triangles, on the rest configuration.
#pragma once

#include <span>

#include "edgefem/core/scene.hpp"

namespace edgefem {

// out (3 #V) += scale x the load's nodal forces (N) at the rest positions X
// (3 #V): per triangle, f = (traction - pressure n) A with n the
// outward unit normal and A the area, a third to each vertex. The total is
// exactly sum_T f_T; for a pressure on a closed surface it is zero (up to
// round-off). InvalidArgument for a vertex out of range.
void add_surface_load_forces(std::span<const double> X, const SurfaceLoad& load, double scale, std::span<double> out);

}  // namespace edgefem
