// The Simulator: the state (state.hpp) on its back-end, the scene's
// integrator (integrators/), its linear solver (solvers/) and the step
// control with the energy guard, put together; the public members read and
// write the state.
#include "edgefem/core/simulator.hpp"

#include <type_traits>
#include <utility>

#include "edgefem/core/finite_input.hpp"
#include "edgefem/core/in_use_flag.hpp"
#include "edgefem/core/output_file.hpp"
#include "simulator/checkpoint_file.hpp"
#include "integrators/static_solve.hpp"
#include "simulator/host_views.hpp"
#include "integrators/time_integrator.hpp"
#include "simulator/step_control.hpp"

namespace edgefem {

template <class S>
struct Simulator<S>::Impl {
    sim::SimState<S> state;
    sim::TangentSolve<S> solve;
    std::unique_ptr<sim::TimeIntegrator<S>> integrator;
    sim::StepControl<S> control;
    sim::HostViews<S> views;
    InUseFlag in_use;

    Impl(Scene scene, std::shared_ptr<const Backend<S>> backend)
        : state(std::move(scene), std::move(backend)),
          solve(state),
          integrator(sim::make_time_integrator(state, solve)),
          control(state, *integrator) {
        if (!integrator->builds_stiffness()) state.op->keep_state(false);
    }

    // The state and loads the application may have written: finite, or the
    // call is refused naming them (before anything changes). The back-end's
    // reduction first; the host copies only to name a bad value.
    void check_inputs() const {
        const std::size_t n = state.n();
        if (state.kernels.first_non_finite(state.u.data(), state.v.data(), n) == n &&
            state.kernels.first_non_finite(state.fext.data(), state.fext.data(), n) == n)
            return;
        std::vector<S> copy;
        require_finite_vectors(state.u.read_host(copy), "displacement");
        require_finite_vectors(state.v.read_host(copy), "velocity");
        require_finite_vectors(state.fext.read_host(copy), "external_forces");
    }

    // Marks the views' copies stale when it goes (also on an exception).
    struct Changed {
        const sim::HostViews<S>& v;
        ~Changed() { v.changed(); }
    };

    // Runs `call` on the state, one thread at a time (`name` the public
    // call): the written views synced in and checked first, the views'
    // copies stale after (also when it throws).
    template <class Call>
    decltype(auto) on_state(const char* name, Call&& call) {
        const InUseFlag::Claim claim(in_use, name);
        views.sync();
        check_inputs();
        const Changed changed{views};
        return call();
    }

    sim::Fingerprint fingerprint(const std::string& numbering) const {
        const Scene& sc = state.scene;
        sim::Fingerprint p;
        p.scalar = std::is_same_v<S, float> ? "float" : "double";
        p.integrator = to_string(sc.integrator);
        p.solver = sc.solver.linear_solver == LinearSolver::Direct
                       ? std::string("direct")
                       : std::string("cg/") + to_string(sc.solver.preconditioner);
        p.numbering = numbering;
        p.vertices = std::uint64_t(sc.mesh.num_vertices());
        p.tets = std::uint64_t(sc.mesh.num_tets());
        p.mesh_hash = mesh_hash(sc.mesh);
        p.backend = state.backend->name();
        return p;
    }
    // The state's bytes, in the order apply() reads them.
    std::string state_bytes() const {
        sim::CheckpointWriter w;
        state.save(w);
        control.save(w);
        integrator->save(w);
        solve.save(w);
        return std::move(w.bytes());
    }
    void apply(std::string_view bytes, const std::string& path) {
        sim::CheckpointReader r(bytes, path);
        state.load(r);
        control.load(r);
        integrator->load(r);
        solve.load(r);
        if (!r.done()) r.fail("state", "bytes left over");
    }

    void save_checkpoint(const std::string& path, const std::string& numbering) {
        on_state("save_checkpoint", [&] {
            write_file_atomically(path, sim::checkpoint_file(fingerprint(numbering), state_bytes()));
        });
    }
    // Everything is checked before the state changes; a state that does not
    // parse after a good checksum (a writer's bug) puts the old one back.
    void load_checkpoint(const std::string& path, const std::string& numbering) {
        const InUseFlag::Claim claim(in_use, "load_checkpoint");
        views.sync();
        const Changed changed{views};
        const std::string bytes = sim::read_checkpoint_file(path, fingerprint(numbering));
        const std::string backup = state_bytes();
        try {
            apply(bytes, path);
        } catch (...) {
            apply(backup, path);
            throw;
        }
    }

    Energies energies() {
        const InUseFlag::Claim claim(in_use, "energies");
        views.sync();
        check_inputs();
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
    Impl& m = self();
    return m.on_state("step", [&]() -> const StepStats& { return m.control.step(); });
}
template <class S>
StaticResult Simulator<S>::solve_static(const StaticProgressFn& progress) {
    Impl& m = self();
    try {
        return m.on_state("solve_static", [&] { return sim::solve_static(m.state, m.solve, progress); });
    } catch (const sim::StepFailure& failure) {
        throw SimulationError("static solve: " + failure.message, self().state.step, failure.vertex);
    }
}
template <class S>
std::span<S> Simulator<S>::displacement() {
    return self().views.writable(self().state.u, sim::HostViews<S>::U);
}
template <class S>
std::span<S> Simulator<S>::velocity() {
    return self().views.writable(self().state.v, sim::HostViews<S>::V);
}
template <class S>
std::span<S> Simulator<S>::external_forces() {
    return self().views.writable(self().state.fext, sim::HostViews<S>::Fext);
}
template <class S>
std::span<const S> Simulator<S>::forces() const {
    return self().views.readable(self().state.f, sim::HostViews<S>::F);
}
template <class S>
std::span<const double> Simulator<S>::lumped_mass() const {
    return self().state.mass_host;
}
template <class S>
std::vector<double> Simulator<S>::positions() const {
    self().views.sync();
    const auto& s = self().state;
    std::vector<S> u_copy;
    const std::span<const S> u = s.u.read_host(u_copy);
    std::vector<double> x(s.n());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = s.scene.mesh.X[i] + double(u[i]);
    return x;
}
template <class S>
void Simulator<S>::save_checkpoint(const std::string& path, const std::string& numbering) {
    self().save_checkpoint(path, numbering);
}
template <class S>
void Simulator<S>::load_checkpoint(const std::string& path, const std::string& numbering) {
    self().load_checkpoint(path, numbering);
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
