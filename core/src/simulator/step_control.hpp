// One step of scene.dt: the integrator's step with the energy guard and the
// finiteness check after it, retried as two halves on a failure (up to
// SolverSettings::max_step_halvings deep; the integrator's history is
// restored with u and v); a step that still fails restores the state it
// started from and throws SimulationError.
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
    void save(CheckpointWriter& w) const { guard_.save(w); }
    void load(CheckpointReader& r) { guard_.load(r); }

private:
    void advance(double T, int depth);

    SimState<S>& s_;
    TimeIntegrator<S>& integrator_;
    EnergyGuard<S> guard_;
    BackendVector<S> step_start_u_, step_start_v_;  // the state before the step (restored when it fails)
    History<S> step_start_history_;                 // and the integrator's history
};

extern template class StepControl<double>;
extern template class StepControl<float>;

}  // namespace edgefem::sim
