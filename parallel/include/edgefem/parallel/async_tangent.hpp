// An asynchronous tangent for fixed-rate loops (haptics, games): the
// stiffness K used by the solver is built on a background thread from a
// recent state and swapped in when ready, so a step never waits for it.
//
//   Simulator<double> sim(scene, nullptr, async_tangent_factory<double>());
//
// The operator forwards forces, energy and the inverted-tet count to a
// foreground operator (the current state, every step). build_stiffness()
// never computes K on the caller's thread except the first time: it swaps
// in the K that the background thread finished since the last call (if
// any) and starts the next build from the latest forces() state. multiply(),
// diagonal_blocks() and for_each_block() use the swapped-in K.
//
// So K lags the state by the time one build takes (one or two steps at
// haptic rates) — the same approximation as SolverSettings::
// stiffness_interval, with the lag set by the clock instead of a count. The
// result therefore depends on timing: runs are not bitwise reproducible.
// Use it where meeting the deadline matters more than reproducibility.
#pragma once

#include "edgefem/core/simulator.hpp"

namespace edgefem {

// `inner` builds the three operators (foreground, and the two tangents that
// alternate between being built and being used); empty: core's serial
// operators, which is what a 2-core machine wants (the loop on one core,
// the tangent on the other).
template <class S>
OperatorFactory<S> async_tangent_factory(OperatorFactory<S> inner = {});

}  // namespace edgefem
