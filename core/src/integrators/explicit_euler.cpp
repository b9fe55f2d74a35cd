// Symplectic Euler: v' = (v + T M^-1 (h - f(u))) / (1 + T alpha), u' = u +
// T v'; the constrained dofs move to their targets. Never builds K.
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class ExplicitEuler final : public TimeIntegrator<S> {
public:
    explicit ExplicitEuler(SimState<S>& state) : s_(state) {}
    bool builds_stiffness() const override { return false; }

    std::optional<double> step(double T) override {
        s_.start_forces();
        s_.external(1.0);
        const double damp = 1 + T * s_.scene.rayleigh_alpha;
        s_.kernels.explicit_velocity(s_.x.data(), s_.v.data(), s_.h.data(), s_.f.data(), s_.mass.data(), T, damp, s_.n());
        s_.constrained_velocities(T, s_.time + T, s_.x.data());
        s_.take_velocity(T);
        return std::nullopt;
    }

private:
    SimState<S>& s_;
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_explicit_euler(SimState<S>& state) {
    return std::make_unique<ExplicitEuler<S>>(state);
}

template std::unique_ptr<TimeIntegrator<double>> make_explicit_euler(SimState<double>&);
template std::unique_ptr<TimeIntegrator<float>> make_explicit_euler(SimState<float>&);

}  // namespace edgefem::sim
