// Static equilibrium under gravity, external forces and the prescribed
// targets, by Newton (newton.hpp) with automatic load stepping: the load
// fraction rises in increments that halve on a failure (12 halvings at
// most). Out: the equilibrium as the state (velocity zero).
#pragma once

#include "integrators/newton.hpp"

namespace edgefem::sim {

template <class S>
StaticResult solve_static(SimState<S>& state, TangentSolve<S>& solve, const StaticProgressFn& progress = {});

}  // namespace edgefem::sim
