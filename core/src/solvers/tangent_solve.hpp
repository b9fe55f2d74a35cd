// The linear solve of an implicit step: builds K at the operator's last
// forces() state (definite if asked), sets up the scene's SystemSolver and
// solves A x = b with the state's b and x (x: the constrained values and a
// warm start). On negative curvature with the plain K (edge method) it
// retries once with the definite K. Times go to StepStats (stiffness_ms,
// solve_ms) with the iterations.
#pragma once

#include <memory>

#include "solvers/system_solver.hpp"
#include "solvers/tangent_point.hpp"

namespace edgefem::sim {

// What a solve does with K: build it at the operator's last forces() state
// (and set up the solver), take the one SimState::build_stiffness() built
// since that state (and set up the solver on it), or reuse the K and
// set-up of an earlier solve where the solver allows (SolverSettings::
// stiffness_interval).
enum class Stiffness { Build, Built, Reuse };

template <class S>
class TangentSolve {
public:
    explicit TangentSolve(SimState<S>& state);

    LinearSystem<S>& system() { return system_; }

    // A = c_m M + c_k K + c_b K0 (K0: null when c_b = 0).
    // `stiffness`: see Stiffness (a retry builds the definite K).
    // `fixed_iterations` > 0: exactly that many CG iterations (the
    // semi-implicit step's budget, cg_fixed_iterations; Newton's solves
    // always run to their tolerance: with the budget they failed to
    // converge).
    // `direction`: SystemSolver::solve's (the warm start improved along it).
    CgResult solve(double c_m, double c_k, double c_b, const ElasticOperator<S>* K0, double tolerance, bool definite,
                   Stiffness stiffness = Stiffness::Build, int fixed_iterations = 0, const double* direction = nullptr);
    // The same without the retry.
    CgResult solve_once(double c_m, double c_k, double c_b, const ElasticOperator<S>* K0, double tolerance,
                        bool definite, Stiffness stiffness = Stiffness::Build, int fixed_iterations = 0,
                        const double* direction = nullptr);

    // For a checkpoint: the solver's set-up that may outlive a step and the
    // lagged K (stiffness_interval > 1); load() rebuilds them.
    void save(CheckpointWriter& w) const;
    void load(CheckpointReader& r);

private:
    SimState<S>& s_;
    LinearSystem<S> system_;
    std::unique_ptr<SystemSolver<S>> solver_;
    TangentPoint<S> lagged_;  // the last K built, with stiffness_interval > 1
};

extern template class TangentSolve<double>;
extern template class TangentSolve<float>;

}  // namespace edgefem::sim
