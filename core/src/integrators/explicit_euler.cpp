// Symplectic Euler: v' = (v + T M^-1 (h - f(u) - beta K(u) v)) / (1 + T
// alpha), u' = u + T v'; the constrained dofs move to their targets.
// Builds K (at u, with the scene's definite_stiffness, as the implicit
// integrators' damping tangent) only for stiffness damping, beta > 0: one
// K and one product with it per step. Stable below 2 / omega_max without
// beta, 2 (sqrt(1 + xi^2) - xi) / omega_max with it (xi = beta omega_max
// / 2), about 2 / (beta omega_max^2) once xi >> 1: stiffness damping
// shortens the explicit step.
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class ExplicitEuler final : public TimeIntegrator<S> {
public:
    explicit ExplicitEuler(SimState<S>& state)
        : s_(state), v_(state.template vector<double>(0)), kv_(state.template vector<double>(0)) {}
    bool builds_stiffness() const override { return s_.scene.rayleigh_beta > 0; }

    std::optional<double> step(double T) override {
        s_.start_forces();
        s_.external(1.0);
        if (s_.scene.rayleigh_beta > 0) stiffness_damping();
        const double damp = 1 + T * s_.scene.rayleigh_alpha;
        s_.kernels.explicit_velocity(s_.x.data(), s_.v.data(), s_.h.data(), s_.f.data(), s_.mass.data(), T, damp, s_.n());
        s_.constrained_velocities(T, s_.time + T, s_.x.data());
        s_.take_velocity(T);
        return std::nullopt;
    }

private:
    // h -= beta K(u) v, K built at the step's u (start_forces left the
    // operator there).
    void stiffness_damping() {
        const std::size_t n = s_.n();
        s_.build_stiffness();
        v_.resize(n);
        kv_.resize(n);
        s_.kernels.from_state(v_.data(), s_.v.data(), n);
        s_.multiply(*s_.op, v_.data(), kv_.data());
        s_.kernels.axpby(s_.h.data(), -s_.scene.rayleigh_beta, kv_.data(), 1.0, n);
    }

    SimState<S>& s_;
    BackendVector<double> v_, kv_;  // v and K v
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_explicit_euler(SimState<S>& state) {
    return std::make_unique<ExplicitEuler<S>>(state);
}

template std::unique_ptr<TimeIntegrator<double>> make_explicit_euler(SimState<double>&);
template std::unique_ptr<TimeIntegrator<float>> make_explicit_euler(SimState<float>&);

}  // namespace edgefem::sim
