// The tests' soft cantilevers: boxes of 1 cm cubes (make_box) clamped at
// x = min, under gravity -z.
#pragma once

#include <algorithm>
#include <limits>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/scene.hpp"

namespace edgefem::test {

// nx x ny x nz cubes of `cell` metres, Young's modulus `young` (Poisson 0.3,
// density 1000), the vertices at the smallest x fixed; integrator and solver
// defaults.
inline Scene clamped_box_scene(int nx, int ny, int nz, double young = 2e4, double cell = 0.01) {
    Scene s;
    s.mesh = make_box(nx, ny, nz, cell);
    s.materials = Material{young, 0.3, 1000};
    s.gravity = {0, 0, -9.81};
    double xmin = std::numeric_limits<double>::infinity();
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v) xmin = std::min(xmin, s.mesh.X[3 * v]);
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
        if (s.mesh.X[3 * v] < xmin + 1e-9) s.fixed.push_back(v);
    return s;
}

// Released from a bend about the clamped end x = x0: u_z = r L t^2, t = (x -
// x0) / L, L the box's length, r the tip's displacement over L.
inline void bend_from_clamp(Scene& s, double r) {
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0;
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
        x0 = std::min(x0, s.mesh.X[3 * v]), x1 = std::max(x1, s.mesh.X[3 * v]);
    s.initial_displacement.assign(s.mesh.X.size(), 0.0);
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v) {
        const double t = (s.mesh.X[3 * v] - x0) / (x1 - x0);
        s.initial_displacement[3 * std::size_t(v) + 2] = r * (x1 - x0) * t * t;
    }
}

// The stress suite's nearly incompressible bar: 6 x 2 x 2 cubes, Y = 1e5 Pa,
// nu = 0.499, alpha = 10 /s, no gravity, released from the bend u_z = 0.2 L
// s^2 (s = x / L), dt = 1 ms, the energy guard at 2, `halvings` step
// halvings; rho_inf for generalized-alpha.
inline Scene bent_incompressible_bar(Integrator integrator, double rho_inf, int halvings) {
    Scene s = clamped_box_scene(6, 2, 2, 1e5);
    s.materials = Material{1e5, 0.499, 1000};
    s.gravity = {0, 0, 0};
    s.rayleigh_alpha = 10;
    s.integrator = integrator;
    s.integrator_parameters.rho_inf = rho_inf;
    s.dt = 1e-3;
    s.solver.max_energy_growth = 2;
    s.solver.max_step_halvings = halvings;
    bend_from_clamp(s, 0.2);
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
