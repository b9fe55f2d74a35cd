// The Simulator: the state (state.hpp) on its back-end, the scene's
// integrator (integrators/), its linear solver (solvers/) and the step
// control with the energy guard, put together; the public members read and
// write the state.
#include "edgefem/core/simulator.hpp"

#include <utility>

#include "integrators/static_solve.hpp"
#include "integrators/time_integrator.hpp"
#include "simulator/step_control.hpp"

namespace edgefem {

template <class S>
struct Simulator<S>::Impl {
    sim::SimState<S> state;
    sim::TangentSolve<S> solve;
    std::unique_ptr<sim::TimeIntegrator<S>> integrator;
    sim::StepControl<S> control;

    Impl(Scene scene, std::shared_ptr<const Backend<S>> backend)
        : state(std::move(scene), std::move(backend)),
          solve(state),
          integrator(sim::make_time_integrator(state, solve)),
          control(state, *integrator) {
        if (!integrator->builds_stiffness()) state.op->keep_state(false);
    }

    Energies energies() {
        const auto& s = state;
        Energies e;
        e.elastic = s.op->energy(s.u.data());
        std::vector<S> u_copy, v_copy;
        const std::span<const S> u = s.u.read_host(u_copy), v = s.v.read_host(v_copy);
        for (std::size_t i = 0; i < s.n(); ++i) {
            const double m = s.mass_host[i / 3];
            e.kinetic += 0.5 * m * double(v[i]) * double(v[i]);
            e.gravity -= m * s.scene.gravity[i % 3] * (s.scene.mesh.X[i] + double(u[i]));
        }
        return e;
    }
};

template <class S>
Simulator<S>::Simulator(Scene scene, std::shared_ptr<const Executor> executor, OperatorFactory<S> factory)
    : impl_(std::make_unique<Impl>(std::move(scene), make_cpu_backend<S>(std::move(executor), std::move(factory)))) {}
template <class S>
Simulator<S>::Simulator(Scene scene, std::shared_ptr<const Backend<S>> backend)
    : impl_(std::make_unique<Impl>(std::move(scene), std::move(backend))) {}
template <class S>
Simulator<S>::~Simulator() = default;
template <class S>
typename Simulator<S>::Impl& Simulator<S>::self() const {
    if (!impl_) throw Error("Simulator: used after it was moved from");
    return *impl_;
}
template <class S>
Simulator<S>::Simulator(Simulator&&) noexcept = default;
template <class S>
Simulator<S>& Simulator<S>::operator=(Simulator&&) noexcept = default;

template <class S>
const Scene& Simulator<S>::scene() const {
    return self().state.scene;
}
template <class S>
index_t Simulator<S>::num_vertices() const {
    return self().state.scene.mesh.num_vertices();
}
template <class S>
const StepStats& Simulator<S>::step() {
    return self().control.step();
}
template <class S>
StaticResult Simulator<S>::solve_static() {
    try {
        return sim::solve_static(self().state, self().solve);
    } catch (const sim::StepFailure& failure) {
        throw SimulationError("static solve: " + failure.message, self().state.step, failure.vertex);
    }
}
template <class S>
std::span<S> Simulator<S>::displacement() {
    return self().state.u.host();
}
template <class S>
std::span<S> Simulator<S>::velocity() {
    return self().state.v.host();
}
template <class S>
std::span<S> Simulator<S>::external_forces() {
    return self().state.fext.host();
}
template <class S>
std::span<const S> Simulator<S>::forces() const {
    return std::as_const(self().state.f).host();
}
template <class S>
std::span<const double> Simulator<S>::lumped_mass() const {
    return self().state.mass_host;
}
template <class S>
std::vector<double> Simulator<S>::positions() const {
    const auto& s = self().state;
    std::vector<S> u_copy;
    const std::span<const S> u = s.u.read_host(u_copy);
    std::vector<double> x(s.n());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = s.scene.mesh.X[i] + double(u[i]);
    return x;
}
template <class S>
Energies Simulator<S>::energies() {
    return self().energies();
}
template <class S>
long Simulator<S>::step_index() const {
    return self().state.step;
}
template <class S>
double Simulator<S>::time() const {
    return self().state.time;
}
template <class S>
const StepStats& Simulator<S>::last_stats() const {
    return self().state.stats;
}

template class Simulator<double>;
template class Simulator<float>;

}  // namespace edgefem
