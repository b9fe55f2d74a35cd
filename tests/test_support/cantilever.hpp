// The tests' soft cantilever: 8 x 2 x 2 cubes of 1 cm (make_box), clamped
// at x = min, gravity -z, Y = 2e4 Pa, CG to 1e-10.
#pragma once

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/scene.hpp"

namespace edgefem::test {

inline Scene cantilever_scene(Integrator integrator = Integrator::SemiImplicit, double dt = 1e-3) {
    Scene s;
    s.mesh = make_box(8, 2, 2);
    s.materials = Material{2e4, 0.3, 1000};
    s.gravity = {0, 0, -9.81};
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
        if (s.mesh.X[3 * v] < -0.04 + 1e-9) s.fixed.push_back(v);
    s.integrator = integrator;
    s.dt = dt;
    s.solver.cg_tolerance = 1e-10;
    s.solver.cg_max_iterations = 2000;
    return s;
}

}  // namespace edgefem::test
