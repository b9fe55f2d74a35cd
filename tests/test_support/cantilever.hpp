// The tests' soft cantilevers: boxes of 1 cm cubes (make_box) clamped at
// x = min, under gravity -z.
#pragma once

#include <algorithm>
#include <limits>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/scene.hpp"

namespace edgefem::test {

// nx x ny x nz cubes, Young's modulus `young` (Poisson 0.3, density 1000),
// the vertices at the smallest x fixed; integrator and solver defaults.
inline Scene clamped_box_scene(int nx, int ny, int nz, double young = 2e4) {
    Scene s;
    s.mesh = make_box(nx, ny, nz);
    s.materials = Material{young, 0.3, 1000};
    s.gravity = {0, 0, -9.81};
    double xmin = std::numeric_limits<double>::infinity();
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v) xmin = std::min(xmin, s.mesh.X[3 * v]);
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
        if (s.mesh.X[3 * v] < xmin + 1e-9) s.fixed.push_back(v);
    return s;
}

// 8 x 2 x 2 cubes, Y = 2e4 Pa, CG to 1e-10.
inline Scene cantilever_scene(Integrator integrator = Integrator::SemiImplicit, double dt = 1e-3) {
    Scene s = clamped_box_scene(8, 2, 2);
    s.integrator = integrator;
    s.dt = dt;
    s.solver.cg_tolerance = 1e-10;
    s.solver.cg_max_iterations = 2000;
    return s;
}

}  // namespace edgefem::test
