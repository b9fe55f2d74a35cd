// Newton with a backtracking line search on an incremental potential:
// dynamic (T > 0) phi(u) = W(u) - h.u + |u - upred|_M^2 / (2 T^2) + the
// damping terms, static (T = 0) phi(u) = W(u) - h.u. Shared by the implicit
// step and the static solve. In: the state's u (constrained dofs at their
// values) and h. Out: u at the minimum, f and W there; StepFailure when it
// cannot converge.
#pragma once

#include "solvers/tangent_solve.hpp"

namespace edgefem::sim {

template <class S>
class Newton {
public:
    Newton(SimState<S>& state, TangentSolve<S>& solve) : s_(state), solve_(solve), d_(state.template vector<double>(0)) {}

    // u0: u at the step's start, upred = u0 + T v (3 #V in the back-end's
    // memory; null when static). K0: the damping tangent when
    // scene.rayleigh_beta > 0, else null.
    void solve(double T, const double* u0, const double* upred, const ElasticOperator<S>* K0);
    // The elastic energy at its last evaluation (the final u).
    double energy() const { return W_; }

private:
    SimState<S>& s_;
    TangentSolve<S>& solve_;
    BackendVector<double> d_;  // u - u0 in the residual
    double W_ = 0;
};

extern template class Newton<double>;
extern template class Newton<float>;

}  // namespace edgefem::sim
