// The state a Simulator advances, shared by its integrators, solvers and
// energy guard: the scene, the back-end with its kernels, the elastic
// operator, the lumped mass, the vectors (3 #V each, in the back-end's
// memory), the constraints, the time and the step's statistics.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "edgefem/core/simulator.hpp"

namespace edgefem::sim {

class CheckpointWriter;
class CheckpointReader;

// A failed step, caught to retry with a halved step.
struct StepFailure {
    std::string message;
    index_t vertex;
};

// An integrator's history beyond u and v (Newmark's acceleration, BDF2's
// previous step), saved and restored with u and v by step control. dt: the
// step size it was made with; u_end, v_end: the state it belongs to (when
// the application has written u or v since, it is stale).
template <class S>
struct History {
    std::vector<BackendVector<double>> vectors;
    BackendVector<S> u_end, v_end;
    double dt = 0;
    bool valid = false;
};

template <class S>
struct SimState {
    Scene scene;
    std::shared_ptr<const Backend<S>> backend;
    const VectorKernels<S>& kernels;
    std::unique_ptr<ElasticOperator<S>> op;
    std::vector<double> mass_host;          // #V, on the host: lumped_mass(), the assembled system
    std::vector<std::uint8_t> free_host;    // 3 #V, on the host: the assembled system's numbering
    BackendVector<double> mass;             // #V
    BackendVector<double> mass_dof;         // 3 #V: mass per dof, for loops that vectorise
    BackendVector<S> u, v, fext, f;         // 3 #V
    BackendVector<std::uint8_t> free_dof;   // 3 #V: 1 on unknowns
    BackendVector<index_t> con_vertex;      // fixed and prescribed vertices
    BackendVector<double> con_disp;         // their final displacement (3 each)
    double ramp_floor = 0;                  // 1 after solve_static: the prescribed targets are reached
    bool forces_current = false;  // f is at the step's starting u: the step skips its force pass
    // The scene's loads (scene.load and the surface loads' nodal forces),
    // grouped by keyframes: the sum of each group's vector x its s(t).
    struct LoadGroup {
        std::vector<Keyframe> keys;
        std::vector<double> force;  // 3 #V
    };
    std::vector<LoadGroup> load_groups;
    BackendVector<double> scene_load;  // one group's force, or all groups' at the last time (3 #V; empty: none)
    BackendVector<S> fext_step;        // with a scene load: f_ext + its keyframed value over the step
    BackendVector<double> h;      // external load (external())
    BackendVector<double> b, x;   // the linear solves' right-hand side and solution
    History<S> history;           // the integrator's (integrators/time_integrator.hpp)
    BackendVector<S> damping_u;   // the u of the last damping tangent K0 (build_damping_tangent)
    BackendVector<S> product_in, product_out;  // multiply()'s copies of its vectors (float models)
    StepStats stats;
    // Called with the relative residual at every Newton iteration when set
    // (solve_static's progress).
    std::function<void(double)> newton_observer;
    long step = 0;
    double time = 0;

    // Validates the scene, builds the operator (on the CPU back-end on one
    // thread when `back` is null) and the lumped mass; the state at rest.
    SimState(Scene s, std::shared_ptr<const Backend<S>> back);

    std::size_t n() const { return u.size(); }
    // n zeros in the back-end's memory.
    template <class T>
    BackendVector<T> vector(std::size_t size) const {
        return backend->template vector<T>(size);
    }
    ConstraintView constraints() const { return {con_vertex.data(), con_disp.data(), con_vertex.size()}; }
    // dst = src (dst resized).
    void copy_state(BackendVector<S>& dst, const BackendVector<S>& src) const;

    // External load h = load (M g + f_ext), f_ext the step's (fext_now()).
    void external(double load);
    // The external force of a step from now: the application's f_ext plus
    // the scene's load at time t (keyframed; the step's midpoint).
    void update_load(double t);
    const S* fext_now() const { return scene_load.size() ? fext_step.data() : fext.data(); }
    // Fraction of the prescribed targets reached at time t (the keyframes,
    // else the ramp over prescribed_steps).
    double ramp(double t) const;
    // Constrained velocities that reach the targets at time t_end.
    void constrained_velocities(double T, double t_end, double* vel) const;
    // x as the new velocity after a step of size T: v = x, u += T x.
    void take_velocity(double T);
    // The constrained displacements at `fraction` of their targets.
    void hold_constraints(double fraction);

    // dst = src (the vectors resized).
    void copy_history(History<S>& dst, const History<S>& src) const;
    // The history's k-th vector, 3 #V (zeros when new).
    double* history_vector(std::size_t k);
    // Whether the history belongs to the current u and v.
    bool history_current() const;
    // The history is complete for the current u and v after a step of dt.
    void history_done(double dt);

    // The damping tangent K0 (Rayleigh beta) at u in `op` (made when null),
    // with the scene's definite_stiffness; u kept as damping_u.
    void build_damping_tangent(std::unique_ptr<ElasticOperator<S>>& op);
    // out = op in with double vectors (a float model's through copies in S).
    void multiply(const ElasticOperator<S>& op, const double* in, double* out);

    // The checkpoint's part of the state (checkpoint_stream.hpp): u, v, the
    // external and the last internal forces, time, step, the ramp's floor and the integrator's
    // history (kept only when it belongs to u and v).
    void save(CheckpointWriter& w) const;
    void load(CheckpointReader& r);

    // f at u (timed as force_ms); W when `energy`.
    double forces(bool energy);
    // K of op at its last forces() state with the scene's
    // definite_stiffness (timed as stiffness_ms), for a step that applies
    // K before or outside a solve (the explicit step's and the linearised
    // steps' stiffness damping).
    void build_stiffness();
    // The internal forces at the step's start, unless the energy guard has
    // just evaluated them at this state.
    void start_forces();

    // StepFailure naming the first non-finite dof of u or v.
    void check_finite(long step_no) const;
    // The vertex with the largest speed (for messages).
    index_t fastest_vertex() const;
};

extern template struct SimState<double>;
extern template struct SimState<float>;

}  // namespace edgefem::sim
