#include "simulator/step_control.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

namespace edgefem::sim {

template <class S>
void StepControl<S>::advance(double T, int depth) {
    // The state is saved only when a failed step may be retried, or the
    // energy guard counts damping from the step's displacement (the whole
    // step's start is kept by step()).
    const bool may_retry = depth < s_.scene.solver.max_step_halvings;
    const bool guard = guard_.enabled();
    // Depth 0 restores the step's start, which step() has just saved (the
    // energy guard reads it too).
    BackendVector<S> u_save = s_.template vector<S>(0), v_save = s_.template vector<S>(0);
    History<S> history_save;
    if ((may_retry || (guard && integrator_.damping_account().from_displacement)) && depth > 0) {
        s_.copy_state(u_save, s_.u);
        s_.copy_state(v_save, s_.v);
    }
    if (may_retry && depth > 0) s_.copy_history(history_save, s_.history);
    const S* u0 = depth == 0 ? step_start_u_.data() : u_save.data();
    const S* v0 = depth == 0 ? step_start_v_.data() : v_save.data();
    try {
        s_.forces_current = false;
        s_.update_load(s_.time + T / 2);
        EnergySample start;
        bool moved = false;
        if (guard) {
            moved = guard_.constraints_move(s_.time + T);
            start = guard_.start(s_.time + T, moved);
        }
        const std::optional<double> W_end = integrator_.step(T);
        s_.check_finite(s_.step + 1);
        // The force pass here, if the step has none at its end, is the one
        // the next step starts with.
        if (guard)
            guard_.check(T, start, u0, v0, W_end ? *W_end : s_.forces(true), moved, integrator_.damping_account());
        s_.time += T;
    } catch (const StepFailure& failure) {
        s_.forces_current = false;
        guard_.forget();
        if (!may_retry) throw;
        s_.copy_state(s_.u, depth == 0 ? step_start_u_ : u_save);
        s_.copy_state(s_.v, depth == 0 ? step_start_v_ : v_save);
        s_.copy_history(s_.history, depth == 0 ? step_start_history_ : history_save);
        ++s_.stats.halvings;
        s_.stats.substep_depth = std::max(s_.stats.substep_depth, depth + 1);
        advance(T / 2, depth + 1);
        advance(T / 2, depth + 1);
    }
}

template <class S>
const StepStats& StepControl<S>::step() {
    s_.stats = StepStats{};
    const double t_start = s_.time;
    // The state before the step, restored when it fails: a failed step
    // left its rejected (often exploded) state behind, and a later step
    // or energies() went on from it as if nothing had happened.
    // Persistent buffers: one copy per step, no allocation.
    s_.copy_state(step_start_u_, s_.u);
    s_.copy_state(step_start_v_, s_.v);
    s_.copy_history(step_start_history_, s_.history);
    try {
        // 2^depth_ pieces (a piece past depth 0 keeps its own start to retry from).
        s_.stats.substep_depth = depth_;
        const int pieces = 1 << depth_;
        for (int k = 0; k < pieces; ++k) advance(s_.scene.dt / pieces, depth_);
    } catch (const StepFailure& failure) {
        s_.time = t_start;
        s_.copy_state(s_.u, step_start_u_);
        s_.copy_state(s_.v, step_start_v_);
        s_.copy_history(s_.history, step_start_history_);
        s_.forces_current = false;
        throw SimulationError(failure.message, s_.step + 1, failure.vertex);
    }
    s_.time = t_start + s_.scene.dt;  // no drift from summed halves
    remember(s_.stats.halvings > 0 ? s_.stats.substep_depth : -1);
    ++s_.step;
    if (s_.scene.count_inverted_tets) s_.stats.inverted_tets = s_.op->inverted_tets(s_.u.data());
    if (s_.scene.solver.fail_on_inverted && s_.stats.inverted_tets > 0)
        throw SimulationError("step " + std::to_string(s_.step) + " ended with " + std::to_string(s_.stats.inverted_tets) +
                                  " inverted tets (negative volume) and solver.fail_on_inverted is set",
                              s_.step);
    return s_.stats;
}

// After a step: `deepest` the depth its halvings reached, -1 if it needed
// none.
template <class S>
void StepControl<S>::remember(int deepest) {
    if (deepest >= 0) {
        const bool repeat = depth_ > 0 || since_up_ < kRepeatWindow;
        hold_ = repeat ? std::min(4 * hold_, kLongestHold) : kFirstHold;
        depth_ = deepest;
        stay_ = hold_;
        return;
    }
    ++since_up_;
    if (depth_ > 0 && --stay_ <= 0) {
        --depth_;
        stay_ = hold_;
        since_up_ = 0;
    }
}

template <class S>
void StepControl<S>::save(CheckpointWriter& w) const {
    guard_.save(w);
    w.value(std::int32_t(depth_));
    w.value(std::int32_t(stay_));
    w.value(std::int32_t(hold_));
    w.value(std::int64_t(since_up_));
}

template <class S>
void StepControl<S>::load(CheckpointReader& r) {
    guard_.load(r);
    const auto depth = r.value<std::int32_t>("step depth");
    const auto stay = r.value<std::int32_t>("step hold left");
    const auto hold = r.value<std::int32_t>("step hold");
    const auto since_up = r.value<std::int64_t>("steps since a shallower level");
    if (depth < 0 || depth > s_.scene.solver.max_step_halvings || stay < 0 || stay > kLongestHold ||
        hold < kFirstHold || hold > kLongestHold || since_up < 0)
        r.fail("step halving state", "out of range");
    depth_ = depth;
    stay_ = stay;
    hold_ = hold;
    since_up_ = since_up;
}

template class StepControl<double>;
template class StepControl<float>;

}  // namespace edgefem::sim
