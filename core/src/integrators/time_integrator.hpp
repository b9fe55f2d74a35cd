// One time step of a given size with the scene's integrator. A new
// integrator is a file with its make_ function and one case in
// make_time_integrator (time_integrator.cpp).
#pragma once

#include <memory>
#include <optional>

#include "simulator/checkpoint_stream.hpp"
#include "simulator/state.hpp"
#include "solvers/tangent_solve.hpp"

namespace edgefem::sim {

// The work of a step's mass damping, as the energy guard counts it: by
// default 2 T alpha x the kinetic energy at the step's end (alpha T |v'|_M^2,
// the work of alpha M v' over du = T v': exact for the Euler steps); with
// `from_displacement`, alpha du . M v_d with v_d = w_new v' + w_old v.
struct DampingAccount {
    bool from_displacement = false;
    double w_new = 1, w_old = 0;
};

template <class S>
class TimeIntegrator {
public:
    virtual ~TimeIntegrator() = default;
    // Advances u and v by T from the state's time (the time itself is the
    // caller's to advance); throws StepFailure. Returns the elastic energy
    // at the new u when the step evaluated it there (the energy guard then
    // needs no force pass of its own).
    virtual std::optional<double> step(double T) = 0;
    // Whether its steps build K (if not, the operator need not keep the
    // state K is built from).
    virtual bool builds_stiffness() const { return true; }
    // How the energy guard counts the work of a step's mass damping.
    virtual DampingAccount damping_account() const { return {}; }
    // Its own state beyond the history (SimState::history), for a checkpoint.
    virtual void save(CheckpointWriter& /*w*/) const {}
    virtual void load(CheckpointReader& /*r*/) {}
};

// The scene's integrator.
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_time_integrator(SimState<S>& state, TangentSolve<S>& solve);

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_explicit_euler(SimState<S>& state);  // explicit_euler.cpp
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_semi_implicit_euler(SimState<S>& state, TangentSolve<S>& solve);
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_implicit_euler(SimState<S>& state, TangentSolve<S>& solve);
// The second-order ones; `linear`: the linearised form (implicit_step.hpp).
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_newmark(SimState<S>& state, TangentSolve<S>& solve, bool linear);
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_generalized_alpha(SimState<S>& state, TangentSolve<S>& solve, bool linear);
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_bdf2(SimState<S>& state, TangentSolve<S>& solve, bool linear);
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_velocity_verlet(SimState<S>& state);

// Newmark's and generalized-alpha's coefficients (newmark.cpp).
struct NewmarkCoefficients {
    double beta, gamma, alpha_m, alpha_f;
};
template <class S>
std::unique_ptr<TimeIntegrator<S>> make_newmark_family(SimState<S>& state, TangentSolve<S>& solve,
                                                       NewmarkCoefficients c, bool linear);

}  // namespace edgefem::sim
