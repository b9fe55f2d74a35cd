// Backward Euler solved by Newton (newton.hpp) from the prediction u0 + T v
// with the constrained dofs at their targets; v' = (u' - u0) / T. With
// Rayleigh beta > 0 the damping uses K0, the tangent at the step's start.
#include "integrators/newton.hpp"
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class ImplicitEuler final : public TimeIntegrator<S> {
public:
    ImplicitEuler(SimState<S>& state, TangentSolve<S>& solve) : s_(state), newton_(state, solve) {}

    std::optional<double> step(double T) override {
        const Scene& scene = s_.scene;
        const std::size_t n = s_.n();
        s_.external(1.0);
        BackendVector<double> u0 = s_.template vector<double>(n), upred = s_.template vector<double>(n);
        s_.kernels.implicit_predict(u0.data(), upred.data(), s_.u.data(), s_.v.data(), T, n);
        if (scene.rayleigh_beta > 0) s_.build_damping_tangent(op_damp_);
        // Start from the prediction with the constrained dofs at their targets.
        const double s = s_.ramp(s_.time + T);
        s_.kernels.to_state(s_.u.data(), upred.data(), n);
        s_.hold_constraints(s);
        const Inertia inertia{1 / (T * T), 1 / T, u0.data(), upred.data()};
        newton_.solve(&inertia, op_damp_.get());
        s_.kernels.implicit_velocity(s_.v.data(), s_.u.data(), u0.data(), T, n);
        return newton_.energy();  // Newton's last evaluation was at the new u
    }

private:
    SimState<S>& s_;
    Newton<S> newton_;
    std::unique_ptr<ElasticOperator<S>> op_damp_;  // K frozen at the step start (beta > 0)
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_implicit_euler(SimState<S>& state, TangentSolve<S>& solve) {
    return std::make_unique<ImplicitEuler<S>>(state, solve);
}

template std::unique_ptr<TimeIntegrator<double>> make_implicit_euler(SimState<double>&, TangentSolve<double>&);
template std::unique_ptr<TimeIntegrator<float>> make_implicit_euler(SimState<float>&, TangentSolve<float>&);

}  // namespace edgefem::sim
