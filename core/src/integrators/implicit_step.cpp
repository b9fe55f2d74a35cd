#include "integrators/implicit_step.hpp"

#include <cmath>
#include <string>

#include "simulator/messages.hpp"

namespace edgefem::sim {

template <class S>
ImplicitStep<S>::ImplicitStep(SimState<S>& state, TangentSolve<S>& solve, bool linear)
    : upred(state.template vector<double>(state.n())), ud(state.template vector<double>(state.n())),
      direction(state.template vector<double>(0)), s_(state),
      solve_(solve), newton_(state, solve), linear_(linear), u0_(state.template vector<double>(state.n())),
      cvel_(state.template vector<double>(state.n())), work_(state.template vector<double>(0)),
      R_(state.template vector<double>(0)), inertia_(state.template vector<double>(0)) {}

template <class S>
void ImplicitStep<S>::begin(double T) {
    const Scene& scene = s_.scene;
    const std::size_t n = s_.n();
    T_ = T;
    s_.start_forces();
    s_.external(1.0);
    s_.kernels.from_state(u0_.data(), s_.u.data(), n);
    s_.constrained_velocities(T, s_.time + T, cvel_.data());
    damping_ = nullptr;
    if (scene.rayleigh_beta <= 0) return;
    if (linear_) {  // the step's K is K0: built once, here, and solved with
        s_.build_stiffness();
        damping_ = s_.op.get();
    } else {
        s_.build_damping_tangent(op_damp_);
        damping_ = op_damp_.get();
    }
}

template <class S>
const double* ImplicitStep<S>::damping_product() {
    if (!damping_) return nullptr;
    const std::size_t n = s_.n();
    R_.resize(n);
    work_.resize(n);
    s_.kernels.from_state(R_.data(), s_.v.data(), n);
    s_.multiply(*damping_, R_.data(), work_.data());
    return work_.data();
}

template <class S>
bool ImplicitStep<S>::warm() const {
    return linear_ && warm_starts(s_.scene.solver);
}

template <class S>
std::optional<double> ImplicitStep<S>::solve(double c_i, double c_d, const double* direction) {
    const double s = s_.ramp(s_.time + T_);
    if (linear_) {
        linear_solve(c_i, c_d, direction);
        return std::nullopt;
    }
    // Newton from the prediction with the constrained dofs at their targets.
    s_.kernels.to_state(s_.u.data(), upred.data(), s_.n());
    s_.hold_constraints(s);
    const Inertia inertia{c_i, c_d, ud.data(), upred.data()};
    newton_.solve(&inertia, damping_);
    return newton_.energy();  // Newton's last evaluation was at the new u
}

// One Newton iteration from the step's start, where f is (start_forces):
// (c_m M + K + c_b K0) du = -R(u0), du = the prediction's as the warm start
// (improved along the scheme's direction) and the targets' on constrained
// dofs; u' = u0 + du. K0 is K here.
template <class S>
void ImplicitStep<S>::linear_solve(double c_i, double c_d, const double* direction) {
    const Scene& scene = s_.scene;
    const VectorKernels<S>& k = s_.kernels;
    const std::size_t n = s_.n();
    const double c_m = c_i + scene.rayleigh_alpha * c_d, c_b = scene.rayleigh_beta * c_d;
    R_.resize(n);
    inertia_.resize(n);
    work_.resize(n);
    BackendVector<double> K0d = s_.template vector<double>(n);  // read (as zeros) when c_b = 0
    k.newton_increment(work_.data(), s_.u.data(), ud.data(), n);
    if (c_b != 0) s_.multiply(*damping_, work_.data(), K0d.data());
    k.newton_residual({R_.data(), inertia_.data(), s_.f.data(), s_.u.data(), s_.h.data(), s_.mass.data(),
                       upred.data(), work_.data(), K0d.data(), s_.free_dof.data(), true, c_i, c_d,
                       scene.rayleigh_alpha, c_b},
                      n);
    k.newton_rhs(s_.b.data(), s_.x.data(), R_.data(), n);
    // x = upred - u0 on free dofs, target - u0 on constrained ones.
    k.to_state(s_.u.data(), upred.data(), n);
    s_.hold_constraints(s_.ramp(s_.time + T_));
    k.newton_increment(s_.x.data(), s_.u.data(), u0_.data(), n);
    k.to_state(s_.u.data(), u0_.data(), n);
    // K0 is K (begin() built it): A = c_m M + (1 + c_b) K, one product per
    // CG iteration. (After negative curvature the retry's definite K is the
    // damping's too.)
    const CgResult res = solve_.solve(c_m, 1.0 + c_b, 0.0, nullptr, scene.solver.cg_tolerance,
                                      scene.solver.definite_stiffness, damping_ ? Stiffness::Built : Stiffness::Build,
                                      scene.solver.cg_fixed_iterations, direction);
    check_linear_solve(s_, res);
    k.line_search_point(s_.u.data(), u0_.data(), s_.x.data(), 1.0, n);
}

template <class S>
void ImplicitStep<S>::finish(double c_v, double* a, double c_a) {
    s_.kernels.history_update(s_.v.data(), a, s_.u.data(), upred.data(), ud.data(), cvel_.data(),
                              s_.free_dof.data(), c_v, c_a, s_.n());
}

template <class S>
void check_linear_solve(SimState<S>& s, const CgResult& res) {
    const SolverSettings& sv = s.scene.solver;
    s.stats.residual = res.residual;
    if (!std::isfinite(res.residual))
        throw StepFailure{"step " + std::to_string(s.step + 1) + ": linear solve failed (non-finite residual)", -1};
    if (!res.converged && sv.cg_fixed_iterations == 0 && sv.linear_solver == LinearSolver::CG) {
        ++s.stats.unconverged_solves;
        if (sv.fail_on_unconverged)
            throw StepFailure{"step " + std::to_string(s.step + 1) + ": CG stopped at " +
                                  std::to_string(res.iterations) + " iterations with relative residual " +
                                  sci(res.residual) + " above the tolerance " + sci(sv.cg_tolerance),
                              -1};
    }
}

template class ImplicitStep<double>;
template class ImplicitStep<float>;
template void check_linear_solve(SimState<double>&, const CgResult&);
template void check_linear_solve(SimState<float>&, const CgResult&);

}  // namespace edgefem::sim
