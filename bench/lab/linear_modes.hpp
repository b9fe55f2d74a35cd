// A scene's linearised dynamics about its rest shape, mode by mode: K at
// rest (the scene's model, edge FE or SN, from the reference back-end) and
// the lumped M on the free dofs (every vertex not in scene.fixed),
// K phi = omega^2 M phi with M-orthonormal phi; and each integrator's
// scalar recurrence on the mode's equation (with Rayleigh damping, which
// the modes diagonalise). On a linear system every integrator of the
// library is a linear recurrence that the modes decouple exactly, so these
// predict a simulator's discrete trajectory (its period error, its
// numerical and Rayleigh damping) from outside the simulator:
// tests/test_modal_dynamics.cpp checks the integrators against them,
// bench/twist_study.cpp explains errors with them. Dense: small meshes only
// (at most 3,000 free dofs).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "edgefem/core/scene.hpp"

namespace edgefem::lab {

struct LinearModes {
    std::vector<std::size_t> dof;  // the free dofs (indices into 3 #V)
    Eigen::VectorXd omega;         // angular frequencies, ascending (rad/s)
    Eigen::MatrixXd phi;           // the modes as columns, phi^T M phi = I
    Eigen::VectorXd mass;          // the lumped mass of each free dof
};

// Throws InvalidArgument for what the recurrences do not model (prescribed
// vertices, gravity or loads), for more than 3,000 free dofs, and as
// Scene::validate() does. Rayleigh damping is modelled (mode_history).
LinearModes linear_modes(const Scene& scene);

// q = phi^T M u (u: 3 #V; its fixed dofs are ignored). Throws
// InvalidArgument where u is too short.
Eigen::VectorXd modal_coordinates(const LinearModes& modes, const std::vector<double>& u);

// u = phi q as `size` (3 #V) displacements, zero at the fixed dofs. Throws
// InvalidArgument for a size too small or a q of another length.
std::vector<double> modal_displacement(const LinearModes& modes, const Eigen::VectorXd& q, std::size_t size);

// x_n for n = 0 .. steps of x'' + (alpha + beta omega^2) x' + omega^2 x = 0
// (Rayleigh damping alpha M + beta K on the mode) from x = 1, x' = 0, by
// the integrator's recurrence at step dt (the linearised forms are their
// Newton forms' recurrences; BDF2 starts with a backward Euler step;
// Newmark and generalized-alpha from the consistent acceleration; the
// explicit step takes alpha implicitly and beta at the step's start).
// Throws InvalidArgument for damping with verlet (the library refuses it).
std::vector<double> mode_history(Integrator integrator, const IntegratorParameters& parameters, double omega,
                                 double dt, long steps, double alpha = 0, double beta = 0);
// The exact x(n dt) = cos(omega n dt), n = 0 .. steps.
std::vector<double> exact_mode_history(double omega, double dt, long steps);

}  // namespace edgefem::lab
