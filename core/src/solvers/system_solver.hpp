// A solver of A x = b for a LinearSystem on the free dofs (constrained dofs
// keep the value they have in x): set up once K is built, then solve.
// One implementation per SolverSettings::linear_solver, each in its file.
#pragma once

#include <memory>

#include "simulator/checkpoint_stream.hpp"
#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
class SystemSolver {
public:
    virtual ~SystemSolver() = default;
    // Whether a set-up may serve later solves (a lagged K,
    // SolverSettings::stiffness_interval).
    virtual bool reusable() const = 0;
    // Symbolic analyses done so far (the direct solver's; 0 for CG).
    virtual int analyses() const { return 0; }
    // Preconditioner set-ups that recomputed its operators so far (the AMG's
    // builds and refreshes; 0 for the others).
    virtual int refreshes() const { return 0; }
    // For A with its K just built (preconditioner, factorisation).
    virtual void setup(LinearSystem<S>& A) = 0;
    // The set-up that may outlive a step, for a checkpoint (the
    // preconditioner's); load() rebuilds it for A.
    virtual void save(CheckpointWriter& /*w*/) const {}
    virtual void load(CheckpointReader& /*r*/, LinearSystem<S>& /*A*/) {}
    // x holds a warm start; `fixed_iterations` > 0: exactly that many
    // iterations (iterative solvers). `direction` (3 #V, zero on
    // constrained dofs; may be null): a direction in which the warm start
    // may be improved first (an iterative solver without a fixed budget
    // moves x along it to the least A-norm error: CgSolver).
    virtual CgResult solve(LinearSystem<S>& A, BackendVector<double>& b, BackendVector<double>& x, double tolerance,
                           int fixed_iterations, const double* direction = nullptr) = 0;
};

// The scene's SolverSettings::linear_solver.
template <class S>
std::unique_ptr<SystemSolver<S>> make_system_solver(const SimState<S>& state);

template <class S>
std::unique_ptr<SystemSolver<S>> make_cg_solver(const SimState<S>& state);      // cg_solver.cpp
template <class S>
std::unique_ptr<SystemSolver<S>> make_direct_solver(const SimState<S>& state);  // direct_solver.cpp

}  // namespace edgefem::sim
