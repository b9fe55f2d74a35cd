// The state a Simulator advances, shared by its integrators, solvers and
// energy guard: the scene, the elastic operator, the lumped mass, the
// vectors (3 #V each), the constraints, the time and the step's
// statistics; and the loops over the dofs that they all run on the
// executor.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "edgefem/core/simulator.hpp"

namespace edgefem::sim {

// A failed step, caught to retry with a halved step.
struct StepFailure {
    std::string message;
    index_t vertex;
};

template <class S>
struct SimState {
    Scene scene;
    std::shared_ptr<const Executor> exec;
    OperatorFactory<S> factory;
    std::unique_ptr<ElasticOperator<S>> op;
    std::vector<double> mass;                     // #V
    std::vector<double> mass_dof;                 // 3 #V: mass per dof, for loops that vectorise
    std::vector<S> u, v, fext, f;                 // 3 #V
    double ramp_floor = 0;                        // 1 after solve_static: the prescribed targets are reached
    std::vector<std::uint8_t> free_dof;           // 3 #V
    std::vector<index_t> con_vertex;              // fixed and prescribed vertices
    std::vector<std::array<double, 3>> con_disp;  // their final displacement
    bool forces_current = false;  // f is at the step's starting u: the step skips its force pass
    std::vector<double> h;        // external load (external())
    std::vector<double> b, x;     // the linear solves' right-hand side and solution
    StepStats stats;
    long step = 0;
    double time = 0;

    // Validates the scene, builds the operator (serial executor and core's
    // operator when exec / factory are empty) and the lumped mass; the
    // state at rest.
    SimState(Scene s, std::shared_ptr<const Executor> e, OperatorFactory<S> make_op);

    std::size_t n() const { return u.size(); }

    // body(i) for every dof / vertex, in fixed blocks on the executor: the
    // per-step O(n) work never runs as a serial section.
    template <class Body>
    void each(Body&& body) const {
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) body(i);
        });
    }
    // dst = src over the dofs' blocks on the executor, as `each` splits
    // them: each thread copies the part of the state it updates. Copied on
    // the calling thread, the whole of u and v passed through its cache once
    // a step, and the other thread's next writes there waited for those
    // lines to be taken back (bunny-4k at 2 threads: the step's u and v
    // update took 9.1 us, 7.7 with the copies here, 1.2 at 1 thread), and
    // the copies were a serial O(n) part of every step.
    template <class T>
    void copy_state(std::vector<T>& dst, const std::vector<T>& src) const {
        dst.resize(src.size());
        for_blocks(*exec, src.size(), [&](std::size_t lo, std::size_t hi) {
            std::copy(src.begin() + std::ptrdiff_t(lo), src.begin() + std::ptrdiff_t(hi), dst.begin() + std::ptrdiff_t(lo));
        });
    }
    // Over the dofs' blocks, each a whole number of vertices (kVectorBlock
    // is a multiple of 3): blocks of kVectorBlock vertices left bunny-4k's
    // 1141 vertices 3 blocks, too few to share, and its preconditioner
    // (a 3x3 inverse per vertex) on one thread.
    template <class Body>
    void each_vertex(Body&& body) const {
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
            for (std::size_t v = lo / 3; v < hi / 3; ++v) body(v);
        });
    }

    // External load h = load (M g + f_ext).
    void external(double load);
    // Fraction of the prescribed targets reached at time t.
    double ramp(double t) const;
    // Constrained velocities that reach the targets at time t_end.
    void constrained_velocities(double T, double t_end, double* vel) const;
    // x as the new velocity after a step of size T: v = x, u += T x.
    void take_velocity(double T);
    // The constrained displacements at `fraction` of their targets.
    void hold_constraints(double fraction);

    // f at u (timed as force_ms); W when `energy`.
    double forces(bool energy);
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
