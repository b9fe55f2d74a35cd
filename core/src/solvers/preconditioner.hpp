// A preconditioner for CG on a LinearSystem: set up after K was built,
// then applied range by range inside the cg kernel's passes (or, for a
// whole-vector one, once per iteration between them).
// One implementation per SolverSettings::preconditioner, each in its file.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>

#include "simulator/checkpoint_stream.hpp"
#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
class Preconditioner : public CgPreconditioner {
public:
    virtual void setup(LinearSystem<S>& A) = 0;
    // The solve it just preconditioned: its iterations (all of them, a
    // change part way included) and the relative residual reached (a lagged
    // set-up decides from them when to refresh).
    virtual void solved(int /*iterations*/, double /*residual*/) {}
    // The set-up that may outlive a step, for a checkpoint; load() rebuilds
    // it (A: the system it preconditions, its coefficients changed).
    virtual void save(CheckpointWriter& /*w*/) const {}
    virtual void load(CheckpointReader& /*r*/, LinearSystem<S>& /*A*/) {}
    // Bytes it holds (the memory figures of docs/solvers.md).
    virtual std::size_t bytes() const = 0;
    // Whether its last set-up found A indefinite (the AMG's coarsest
    // factorisation met a negative pivot). CG then does not see the
    // negative curvature itself (a V-cycle that solves A exactly makes
    // p.Ap = r.A^-1 r, positive), so the solve reports it, as the direct
    // solver's LDL^T does, and the step falls back to the definite K.
    virtual bool indefinite() const { return false; }
    // Set-ups that recomputed its operators so far (StepStats::
    // preconditioner_refreshes).
    virtual int refreshes() const { return 0; }
    // Of those, the ones that built its hierarchy (the AMG's first set-up,
    // and where the body has moved too far from where it was built).
    virtual int rebuilds() const { return 0; }
    // One CG iteration under it, in products with the finest level's
    // matrix (a count, the same on any machine: the auto preconditioner's
    // cost model): block-Jacobi 1, AMG 1 + its V-cycle.
    virtual double iteration_cost() const { return 1; }
    // Makes its next set-up recompute its operators, as for a K far from
    // the last one (the AMG builds its hierarchy again, on the positions
    // there).
    virtual void invalidate() {}
    // A preconditioner that gives way to a stronger one part way through a
    // solve ("auto"; the lagged AMG's refresh part way): the CG iterations
    // after which a solve that has not converged changes preconditioner (0:
    // never), and the change itself, set up on the A being solved, told the
    // relative residual reached. The solve goes on from its iterate.
    virtual int switch_after() const { return 0; }
    virtual void switch_now(LinearSystem<S>& /*A*/, double /*residual*/) {}
};

// Decades of residual reduction a relative residual means (at least
// `floor`): the unit lagged and automatic preconditioners count iterations
// in, as Newton's solves ask for different tolerances.
inline double residual_decades(double residual, double floor = 1) {
    return std::max(floor, -std::log10(std::max(residual, 1e-300)));
}

// The scene's SolverSettings::preconditioner.
template <class S>
std::unique_ptr<Preconditioner<S>> make_preconditioner(const SimState<S>& state);

template <class S>
std::unique_ptr<Preconditioner<S>> make_block_jacobi(const SimState<S>& state);  // block_jacobi.cpp
template <class S>
std::unique_ptr<Preconditioner<S>> make_amg(const SimState<S>& state);           // amg_preconditioner.cpp
template <class S>
std::unique_ptr<Preconditioner<S>> make_auto_preconditioner(const SimState<S>& state);  // auto_preconditioner.cpp

}  // namespace edgefem::sim
