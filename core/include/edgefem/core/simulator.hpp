// The simulator an application links and steps: it owns the scene and the
// state (displacement u = x - X and velocity, in the user's vertex numbering)
// and advances it with the scene's integrator.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <vector>

#include "edgefem/core/backend.hpp"
#include "edgefem/core/checkpoint.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/core/scene.hpp"

namespace edgefem {

// A step or solve that could not produce a finite, converged state. The
// message names the step and, for non-finite state, the vertex.
class SimulationError : public Error {
public:
    SimulationError(const std::string& message, long step, index_t vertex = -1)
        : Error(message), step_(step), vertex_(vertex) {}
    long step() const { return step_; }
    index_t vertex() const { return vertex_; }

private:
    long step_;
    index_t vertex_;
};

struct StepStats {
    double force_ms = 0;      // internal forces (and energy where needed)
    double stiffness_ms = 0;  // building K (and its preconditioner / assembly)
    double solve_ms = 0;      // linear solves
    int solver_iterations = 0;  // CG iterations (summed over Newton iterations)
    int symbolic_analyses = 0;  // direct solver: symbolic analyses done in the step (1 in the first, then 0)
    int preconditioner_refreshes = 0;  // AMG: hierarchy builds and refreshes of its operators in the step
    int newton_iterations = 0;  // Implicit / static
    bool newton_round_off = false;  // Newton stopped at its round-off floor above newton_tolerance
    double residual = 0;        // final relative residual of the last solve
    bool negative_curvature = false;  // CG met p^T A p <= 0 (K indefinite)
    int unconverged_solves = 0;  // semi-implicit CG solves that stopped above their tolerance
    index_t inverted_tets = 0;  // at the end of the step
    int halvings = 0;           // step halvings used
    int substep_depth = 0;      // the step ran as pieces of dt / 2^depth (a halving is remembered: docs/dynamics.md)
    // Energy guard (SolverSettings::max_energy_growth > 0): 1 + the energy
    // gained without a source since its lowest level / the largest kinetic +
    // elastic energy seen, after the step: the ratio the guard bounds.
    double energy_growth = 0;
};

struct Energies {
    double kinetic = 0, elastic = 0, gravity = 0;  // gravity: -m g.x summed (potential)
    double total() const { return kinetic + elastic + gravity; }
};

struct StaticResult {
    int newton_iterations = 0;
    int load_steps = 0;      // load steps finally used
    double residual = 0;     // |R| / |external load + reactions scale|
    bool converged = false;
};

// What solve_static reports at every Newton iteration (including each load
// step's first residual, before an iteration).
struct StaticProgress {
    int load_step = 0;           // the load step being solved, from 1 (a retried, halved step counts again)
    double load_fraction = 0;    // the fraction of the full load it reaches
    int newton_iterations = 0;   // over the whole solve so far
    double residual = 0;         // the relative residual now
};
using StaticProgressFn = std::function<void(const StaticProgress&)>;

template <class S>
class Simulator {
public:
    // Validates the scene (InvalidArgument naming the field) and sets up the
    // model; the state starts at rest (u = 0, v = 0). `executor` runs the
    // solver's vector operations (serial when null); `factory` builds the
    // elastic model (the reference back-end's operator when empty):
    // make_cpu_backend(executor, factory).
    explicit Simulator(Scene scene, std::shared_ptr<const Executor> executor = nullptr,
                       OperatorFactory<S> factory = {});
    // The same on `backend` (the CPU back-end on one thread when null): the
    // state and the solvers' vectors live in its memory, and its kernels run
    // all vector work.
    Simulator(Scene scene, std::shared_ptr<const Backend<S>> backend);
    ~Simulator();
    // A moved-from simulator may only be destroyed or assigned to: its other
    // members throw Error.
    Simulator(Simulator&&) noexcept;
    Simulator& operator=(Simulator&&) noexcept;

    const Scene& scene() const;
    index_t num_vertices() const;

    // Advances by scene().dt with the scene's integrator; throws
    // SimulationError on non-finite state, a failed solve or energy grown
    // without a source (SolverSettings::max_energy_growth), after the
    // allowed step halvings. A step that throws leaves the state (u, v,
    // time, step_index) as it was before the call, so the application can
    // change what made it fail (dt, loads) and step again.
    const StepStats& step();
    // Static equilibrium under gravity, external forces and the prescribed
    // targets (reached fully), by Newton with line search and automatic load
    // stepping; the result becomes the state (velocity zero), and later
    // steps hold the prescribed vertices at their targets. `progress`, when
    // set, is called at every Newton iteration.
    StaticResult solve_static(const StaticProgressFn& progress = {});

    // Views (3 #V, xyz per vertex) of the back-end's vectors: zero-copy in
    // host memory; for a GPU back-end a host copy made when first asked for
    // after a step and, for the writable ones, copied back at the next
    // step (a view stays valid until the next step()). External forces are the
    // application's to change between steps (e.g. a haptic probe); forces()
    // holds the internal elastic forces of the last evaluation.
    std::span<S> displacement();
    std::span<S> velocity();
    std::span<S> external_forces();
    std::span<const S> forces() const;
    std::span<const double> lumped_mass() const;  // #V
    // Current positions X + u (computed, 3 #V).
    std::vector<double> positions() const;

    // Checkpoints (checkpoint.hpp). save_checkpoint writes the whole state
    // to `path`, whole or not at all (OutputFile; IoError when it cannot):
    // u, v, the external forces, time, step index, the integrator's history,
    // the energy guard's sums and the solver set-ups that outlive a step (a
    // lagged K, the AMG's hierarchy), the latter as the states they were
    // built at. load_checkpoint reads it back, rebuilding those set-ups, so
    // that stepping on continues bit for bit as if the run had not stopped
    // (on the same back-end and thread-count-independent variants; another
    // back-end continues from the same state, not with the same bits). It
    // throws CheckpointError naming the file and the problem (unreadable,
    // not a checkpoint, truncated, corrupt, or written for another scalar
    // type, integrator, solver, numbering or mesh) and then leaves the state
    // as it was. `numbering` labels the vertex numbering the state is in
    // (OrderedSimulator passes its ordering's name) and must match too. The
    // scene's other settings (dt, material, loads) are this simulator's.
    void save_checkpoint(const std::string& path, const std::string& numbering = "");
    void load_checkpoint(const std::string& path, const std::string& numbering = "");

    // Energies of the current state (computes the elastic energy).
    Energies energies();
    long step_index() const;
    double time() const;
    const StepStats& last_stats() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    // impl_, or an Error for a moved-from simulator (instead of a null
    // dereference).
    Impl& self() const;
};

extern template class Simulator<double>;
extern template class Simulator<float>;

}  // namespace edgefem
