// Newton with a backtracking line search on an incremental potential:
// dynamic phi(u) = W(u) - h.u + c_i |u - upred|_M^2 / 2 + c_d (alpha
// |u - ud|_M^2 + beta |u - ud|_K0^2) / 2 (backward Euler: c_i = 1 / T^2,
// c_d = 1 / T, ud = u0), static phi(u) = W(u) - h.u. Shared by the implicit
// step and the static solve. In: the state's u (constrained dofs at their
// values) and h. Out: u at the minimum, f and W there; StepFailure when it
// cannot converge.
#pragma once

#include "solvers/tangent_solve.hpp"

namespace edgefem::sim {

// The dynamic terms of the potential: the scheme's coefficients and
// predictions (3 #V each in the back-end's memory).
struct Inertia {
    double c_i, c_d;
    const double* ud;
    const double* upred;
};

template <class S>
class Newton {
public:
    Newton(SimState<S>& state, TangentSolve<S>& solve) : s_(state), solve_(solve), d_(state.template vector<double>(0)) {}

    // `scheme`: null when static. K0: the damping tangent when
    // scene.rayleigh_beta > 0, else null.
    void solve(const Inertia* scheme, const ElasticOperator<S>* K0);
    // The elastic energy at its last evaluation (the final u).
    double energy() const { return W_; }

private:
    SimState<S>& s_;
    TangentSolve<S>& solve_;
    BackendVector<double> d_;  // u - ud in the residual
    double W_ = 0;
};

extern template class Newton<double>;
extern template class Newton<float>;

}  // namespace edgefem::sim
