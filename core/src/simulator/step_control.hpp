// One step of scene.dt: the integrator's step with the energy guard and the
// finiteness check after it, retried as two halves on a failure (up to
// SolverSettings::max_step_halvings deep; the integrator's history is
// restored with u and v); a step that still fails restores the state it
// started from and throws SimulationError.
//
// The halving is remembered: after a step that needed it, the next steps
// start as pieces of the depth that succeeded, kept for a hold of steps
// (64 at first) before one level less deep is tried again. A failure while
// a level is held, or within 4096 steps of a return to a shallower level,
// makes the hold 4x longer (up to 65536 steps); a failure after that starts
// it at 64 again. So a scheme that is unstable at dt but not at dt / 2 (the
// linearised generalized-alpha on a nearly incompressible body,
// docs/dynamics.md), whose instability grows for hundreds of steps before
// the energy guard sees it, ends up running at the stable step instead of
// growing back again and again, and a passing fault costs a hold of halved
// steps per level.
#pragma once

#include "integrators/time_integrator.hpp"
#include "simulator/energy_guard.hpp"

namespace edgefem::sim {

template <class S>
class StepControl {
public:
    StepControl(SimState<S>& state, TimeIntegrator<S>& integrator)
        : s_(state), integrator_(integrator), guard_(state), step_start_u_(state.template vector<S>(0)),
          step_start_v_(state.template vector<S>(0)) {}
    const StepStats& step();
    void save(CheckpointWriter& w) const;
    void load(CheckpointReader& r);

    static constexpr int kFirstHold = 64, kLongestHold = 65536, kRepeatWindow = 4096;

private:
    void advance(double T, int depth);
    void remember(int deepest);

    SimState<S>& s_;
    TimeIntegrator<S>& integrator_;
    EnergyGuard<S> guard_;
    BackendVector<S> step_start_u_, step_start_v_;  // the state before the step (restored when it fails)
    History<S> step_start_history_;                 // and the integrator's history
    // The remembered halving: steps start as 2^depth_ pieces; stay_ more
    // steps before one level less; hold_ the steps a level is kept after a
    // failure; since_up_ the steps since the last return to a shallower
    // level (the depth the current step reached: StepStats::substep_depth).
    int depth_ = 0, stay_ = 0, hold_ = kFirstHold;
    long since_up_ = kRepeatWindow;  // a first failure is no repeat
};

extern template class StepControl<double>;
extern template class StepControl<float>;

}  // namespace edgefem::sim
