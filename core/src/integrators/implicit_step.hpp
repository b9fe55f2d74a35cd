// The step the second-order implicit integrators share. A scheme gives its
// coefficients c_i, c_d and predictions upred, ud and the step solves
//   c_i M (u' - upred) + D c_d (u' - ud) + F(u') = h
// (D = alpha M + beta K0, K0 the tangent at the step's start; h the state's
// load, which the scheme may have changed) for u': by Newton (newton.hpp)
// from upred, or linearised at the step's start (one K, the scene's CG
// tolerance or fixed budget: the real-time form). Then v' = c_d (u' - ud)
// (on constrained dofs the velocity that takes them to their targets) and,
// when asked, a' = c_a (u' - upred).
#pragma once

#include <optional>

#include "integrators/newton.hpp"

namespace edgefem::sim {

template <class S>
class ImplicitStep {
public:
    ImplicitStep(SimState<S>& state, TangentSolve<S>& solve, bool linear);

    // The step's start: f and h at u, K0 (beta > 0), the constrained
    // velocities to t + T.
    void begin(double T);
    // K0 v at the step's start when beta > 0, else null (after begin).
    const double* damping_product();
    // Whether a linearised solve improves its start along a direction (not
    // Newton; warm_starts below).
    bool warm() const;
    // Solves for u' (the state's u) with the scheme's upred and ud; the
    // elastic energy at u' when it was evaluated there (Newton).
    // `direction` (zero on constrained dofs; may be null): the linearised
    // solve's start upred is improved along it (SystemSolver::solve), a
    // scheme's estimate of the shape of u' - upred.
    std::optional<double> solve(double c_i, double c_d, const double* direction = nullptr);
    // v' = c_v (u' - ud), and a' = c_a (u' - upred) when a is not null.
    void finish(double c_v, double* a, double c_a);

    BackendVector<double> upred, ud;  // the scheme's predictions (3 #V)
    BackendVector<double> direction;  // for the scheme's direction, sized by it

private:
    void linear_solve(double c_i, double c_d, const double* direction);

    SimState<S>& s_;
    TangentSolve<S>& solve_;
    Newton<S> newton_;
    bool linear_;
    double T_ = 0;
    BackendVector<double> u0_, cvel_, work_, R_, inertia_;
    std::unique_ptr<ElasticOperator<S>> op_damp_;  // Newton's K0: K frozen at the step start (beta > 0)
    const ElasticOperator<S>* damping_ = nullptr;  // K0 (beta > 0): op_damp_, or the state's K when linear
};

// Whether a linearised step's CG improves its start along a direction from
// the history: SolverSettings::warm_start, and not with a fixed CG budget
// (its iterations' cost is the budget) or the direct solver.
inline bool warm_starts(const SolverSettings& sv) {
    return sv.warm_start && sv.cg_fixed_iterations == 0 && sv.linear_solver == LinearSolver::CG;
}

// A linearised step's solve result: counted, and a failure (a non-finite
// residual; CG above its tolerance without a fixed budget when
// fail_on_unconverged) thrown as StepFailure.
template <class S>
void check_linear_solve(SimState<S>& s, const CgResult& res);

extern template class ImplicitStep<double>;
extern template class ImplicitStep<float>;

}  // namespace edgefem::sim
