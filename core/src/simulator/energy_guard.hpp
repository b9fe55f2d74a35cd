// The energy guard (SolverSettings::max_energy_growth): a step fails when
// the total energy has grown, net of the external work and of what mass
// damping removed, by more than the allowed factor of the largest kinetic +
// elastic energy seen.
// In: the state before and after a step. Out: StepStats::energy_growth, or
// a StepFailure.
#pragma once

#include <cmath>

#include "integrators/time_integrator.hpp"
#include "simulator/checkpoint_stream.hpp"
#include "simulator/state.hpp"

namespace edgefem::sim {

// The guard's view of a state.
struct EnergySample {
    double kinetic = 0, elastic = 0;
    double gravity = 0;  // -m g.u (the constant -m g.X left out: only differences count)
    double load = 0;     // f_ext.u with the step's f_ext: its change is the external work
    // Where constraints move: kinetic, gravity and load over the
    // constrained vertices (the free part is the total less these), and
    // f.(u_c(t_end) - u_c(t_start)), the constrained dofs' forces times
    // their move (half of it is the constraints' work on the body).
    double c_kinetic = 0, c_gravity = 0, c_load = 0, c_work = 0;
    double total() const { return kinetic + elastic + gravity; }
    double magnitude() const { return kinetic + std::abs(elastic) + std::abs(gravity) + std::abs(load); }
};

template <class S>
class EnergyGuard {
public:
    explicit EnergyGuard(SimState<S>& state)
        : s_(state), u_evaluated_(state.template vector<S>(0)), v_free_(state.template vector<double>(0)),
          v_con_(state.template vector<double>(0)), kv_(state.template vector<double>(0)) {}
    bool enabled() const { return s_.scene.solver.max_energy_growth > 0; }

    // The state at the start of a step. The elastic energy comes from the
    // guard's force pass at the end of the last step when u is unchanged
    // since (then f is current too and the step skips its force pass), else
    // from a force pass here. Edits the application made between steps are
    // thereby part of the starting energy, not of the step's gain. With
    // `moved`, also the constrained vertices' terms (EnergySample::c_*).
    EnergySample start(double t_end, bool moved);

    // Whether a step from the current state to t_end moves a fixed or
    // prescribed vertex (a prescribed ramp, or a vertex the application
    // displaced). Such a step's gain is the free vertices' energy change
    // less the constraints' work, f_c . du_c by the trapezoidal rule, and
    // with stiffness damping (beta) less what they did through it, -T beta
    // v_f . K v_c (damping_drag).
    bool constraints_move(double t_end) const;

    // After a failed step: its force passes (Newton's iterates) have
    // overwritten f, so the next start evaluates the forces again.
    void forget() { evaluated_valid_ = false; }

    // After a step of size T that started at `start` (state u0, v0) and
    // ends with elastic energy W_end; `damping`: the integrator's account of
    // mass damping's work (TimeIntegrator::damping_account).
    void check(double T, const EnergySample& start, const S* u0, const S* v0, double W_end, bool constraints_moved,
               const DampingAccount& damping);

    // For a checkpoint: the gain counted and the largest energy seen (the
    // next start evaluates the forces again).
    void save(CheckpointWriter& w) const {
        w.value(energy_excess_);
        w.value(energy_scale_);
    }
    void load(CheckpointReader& r) {
        energy_excess_ = r.value<double>("energy gain");
        energy_scale_ = r.value<double>("energy scale");
        forget();
    }

private:
    EnergySample sample(double W) const;
    void constrained(EnergySample& e, const S* u_from, double fraction) const;
    double damping_drag(double T);

    SimState<S>& s_;
    BackendVector<S> u_evaluated_;  // the u that f, the operator's state and W_evaluated_ belong to
    double W_evaluated_ = 0;
    bool evaluated_valid_ = false;
    double energy_excess_ = 0;  // energy gained net of work since its lowest level (>= 0)
    double energy_scale_ = 0;   // largest kinetic + elastic energy seen
    BackendVector<double> v_free_, v_con_, kv_;  // damping_drag's work (3 #V when used)
};

extern template class EnergyGuard<double>;
extern template class EnergyGuard<float>;

}  // namespace edgefem::sim
