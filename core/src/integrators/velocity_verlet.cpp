// Velocity Verlet (explicit central differences in velocity form): a half
// kick v+ = v + T/2 (M^-1 (h - F(u)) - alpha v), the drift u' = u + T v+
// (constrained dofs: to their targets), the force at u', the second half
// kick v' = (v+ + T/2 M^-1 (h - F(u'))) / (1 + T alpha / 2). Second order
// and symplectic, one force pass per step (the end's force is the next
// step's start), never builds K. Stable below the same dt as symplectic
// Euler (2 / omega_max).
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class VelocityVerlet final : public TimeIntegrator<S> {
public:
    explicit VelocityVerlet(SimState<S>& state) : s_(state) {}
    bool builds_stiffness() const override { return false; }

    std::optional<double> step(double T) override {
        const std::size_t n = s_.n();
        const double alpha = s_.scene.rayleigh_alpha;
        s_.start_forces();
        s_.external(1.0);
        s_.kernels.verlet_kick(s_.x.data(), s_.v.data(), s_.h.data(), s_.f.data(), s_.mass.data(),
                               s_.free_dof.data(), T / 2, alpha, 0, n);
        s_.constrained_velocities(T, s_.time + T, s_.x.data());
        s_.take_velocity(T);
        const double W = s_.forces(true);
        s_.kernels.verlet_kick(s_.x.data(), s_.v.data(), s_.h.data(), s_.f.data(), s_.mass.data(),
                               s_.free_dof.data(), T / 2, 0, alpha, n);
        s_.kernels.to_state(s_.v.data(), s_.x.data(), n);
        return W;  // the energy guard's end state: f there is the next step's start

    }

private:
    SimState<S>& s_;
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_velocity_verlet(SimState<S>& state) {
    return std::make_unique<VelocityVerlet<S>>(state);
}

template std::unique_ptr<TimeIntegrator<double>> make_velocity_verlet(SimState<double>&);
template std::unique_ptr<TimeIntegrator<float>> make_velocity_verlet(SimState<float>&);

}  // namespace edgefem::sim
