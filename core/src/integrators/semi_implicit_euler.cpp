// Linearised backward Euler, one K per step (or per stiffness_interval
// steps): (c_m M + c_k K) v' = M v + T (h - f(u)) with c_m = 1 + T alpha,
// c_k = T beta + T^2, then u' = u + T v'; the constrained dofs move to
// their targets. CG starts from v, improved along the change of velocity
// over the last step (v - v_prev, the history's one vector: the motion
// goes on as it went), by as much as lowers the A-norm error most.
#include "integrators/implicit_step.hpp"
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class SemiImplicitEuler final : public TimeIntegrator<S> {
public:
    SemiImplicitEuler(SimState<S>& state, TangentSolve<S>& solve)
        : s_(state), solve_(solve), direction_(state.template vector<double>(0)) {}

    std::optional<double> step(double T) override {
        const Scene& scene = s_.scene;
        s_.start_forces();
        s_.external(1.0);
        const double c_m = 1 + T * scene.rayleigh_alpha, c_k = T * scene.rayleigh_beta + T * T;
        // x = v: the warm start.
        s_.kernels.semi_implicit_rhs(s_.b.data(), s_.x.data(), s_.v.data(), s_.h.data(), s_.f.data(), s_.mass.data(), T,
                                     s_.n());
        s_.constrained_velocities(T, s_.time + T, s_.x.data());
        // The history's v_prev, where it belongs to this u and v (not
        // after a state the application wrote, nor after a checkpoint
        // without it), where warm_starts allows.
        const bool warm = warm_starts(scene.solver);
        const double* direction = nullptr;
        if (warm) {
            const bool current = s_.history_current();
            double* const v_prev = s_.history_vector(0);
            if (current) {
                direction_.resize(s_.n());
                s_.kernels.velocity_change(direction_.data(), v_prev, s_.v.data(), s_.free_dof.data(), s_.n());
                direction = direction_.data();
            } else {
                s_.kernels.from_state(v_prev, s_.v.data(), s_.n());
            }
        }
        // Reuse K while the interval allows and the step size is the one it
        // was built for (a halved step changes the system matrix).
        const bool reuse = stiffness_age_ > 0 && stiffness_age_ < scene.solver.stiffness_interval && T == stiffness_dt_;
        const CgResult res = solve_.solve(c_m, c_k, 0.0, nullptr, scene.solver.cg_tolerance,
                                          scene.solver.definite_stiffness, reuse ? Stiffness::Reuse : Stiffness::Build,
                                          scene.solver.cg_fixed_iterations,
                                          direction);
        stiffness_age_ = reuse ? stiffness_age_ + 1 : 1;
        stiffness_dt_ = T;
        check_linear_solve(s_, res);
        s_.take_velocity(T);
        if (warm) s_.history_done(T);
        return std::nullopt;
    }

    void save(CheckpointWriter& w) const override {
        w.value(stiffness_age_);
        w.value(stiffness_dt_);
    }
    void load(CheckpointReader& r) override {
        stiffness_age_ = r.value<int>("stiffness age");
        stiffness_dt_ = r.value<double>("stiffness step size");
    }

private:
    SimState<S>& s_;
    TangentSolve<S>& solve_;
    BackendVector<double> direction_;  // v - v_prev on free dofs
    int stiffness_age_ = 0;    // steps since K was built (0: none yet)
    double stiffness_dt_ = 0;  // the step size K's system matrix was built for
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_semi_implicit_euler(SimState<S>& state, TangentSolve<S>& solve) {
    return std::make_unique<SemiImplicitEuler<S>>(state, solve);
}

template std::unique_ptr<TimeIntegrator<double>> make_semi_implicit_euler(SimState<double>&, TangentSolve<double>&);
template std::unique_ptr<TimeIntegrator<float>> make_semi_implicit_euler(SimState<float>&, TangentSolve<float>&);

}  // namespace edgefem::sim
