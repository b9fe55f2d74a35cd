#include "edgefem/partition/ordered_simulator.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/finite_input.hpp"
#include "edgefem/partition/permute_mesh.hpp"

namespace edgefem {

Scene permute_scene(const Scene& scene, const std::vector<index_t>& new_of_old) {
    Scene s = scene;
    s.mesh = permute_mesh(scene.mesh, new_of_old);
    for (index_t& v : s.fixed) v = new_of_old.at(v);
    for (auto& p : s.prescribed) p.vertex = new_of_old.at(p.vertex);
    for (SurfaceLoad& l : s.surface_loads)
        for (auto& t : l.triangles)
            for (index_t& v : t) v = new_of_old.at(v);
    // Per-vertex vectors (3 #V) follow their vertices.
    for (std::vector<double>* x : {&s.load, &s.initial_displacement, &s.initial_velocity}) {
        if (x->size() != 3 * new_of_old.size()) continue;  // empty (or wrong: validate() names it)
        std::vector<double> out(x->size());
        for (std::size_t v = 0; v < new_of_old.size(); ++v)
            for (int r = 0; r < 3; ++r) out[3 * std::size_t(new_of_old[v]) + r] = (*x)[3 * v + r];
        *x = std::move(out);
    }
    return s;
}

namespace {
// A user array of `given` values for a state of `expected` (3 #V): checked,
// as the C API's counts are, since a short span would be read or written
// past its end.
void check_length(std::size_t given, std::size_t expected) {
    if (given != expected)
        throw InvalidArgument("expected 3 x #V = " + std::to_string(expected) + " values (one xyz per vertex), got " +
                              std::to_string(given));
}

template <class From, class To>
void gather(std::span<const From> in, std::span<To> out, const std::vector<index_t>& new_of_old, bool to_internal_order) {
    check_length(to_internal_order ? in.size() : out.size(), 3 * new_of_old.size());
    for (std::size_t v = 0; v < new_of_old.size(); ++v)
        for (int r = 0; r < 3; ++r) {
            const std::size_t user = 3 * v + r, internal = 3 * std::size_t(new_of_old[v]) + r;
            if (to_internal_order)
                out[internal] = To(in[user]);
            else
                out[user] = To(in[internal]);
        }
}
}  // namespace

namespace {
// The ordering, or an empty list when it is the identity.
std::vector<index_t> non_identity(std::vector<index_t> new_of_old) {
    for (std::size_t v = 0; v < new_of_old.size(); ++v)
        if (new_of_old[v] != index_t(v)) return new_of_old;
    return {};
}
}  // namespace

template <class S>
OrderedSimulator<S>::OrderedSimulator(const Scene& scene, Ordering ordering, std::shared_ptr<const Executor> executor,
                                      OperatorFactory<S> factory, const OrderingOptions& options)
    : OrderedSimulator(scene, ordering, make_cpu_backend<S>(std::move(executor), std::move(factory)), options) {}

template <class S>
OrderedSimulator<S>::OrderedSimulator(const Scene& scene, Ordering ordering, std::shared_ptr<const Backend<S>> backend,
                                      const OrderingOptions& options)
    : user_scene_((scene.validate(), scene)),
      ordering_(to_string(ordering)),
      new_of_old_(non_identity(vertex_ordering(scene.mesh, ordering, options))),
      sim_(identity() ? scene : permute_scene(scene, new_of_old_), std::move(backend)) {
    if (identity()) return;
    const std::size_t n = 3 * new_of_old_.size();
    u_.assign(n, S(0));
    v_.assign(n, S(0));
    fext_.assign(n, S(0));
    f_.assign(n, S(0));
    mass_.resize(new_of_old_.size());
    for (std::size_t v = 0; v < new_of_old_.size(); ++v) mass_[v] = sim_.lumped_mass()[new_of_old_[v]];
    pull();
}

namespace {
// The error with its vertex (and the message's "vertex N") in the user's
// numbering.
SimulationError to_user_numbering(const SimulationError& e, const std::vector<index_t>& new_of_old) {
    if (e.vertex() < 0) return e;
    const auto it = std::find(new_of_old.begin(), new_of_old.end(), e.vertex());
    if (it == new_of_old.end()) return e;
    const index_t user = index_t(it - new_of_old.begin());
    std::string message = e.what();
    const std::string internal_name = "vertex " + std::to_string(e.vertex());
    for (std::size_t at = message.find(internal_name); at != std::string::npos;
         at = message.find(internal_name, at + 1)) {
        const std::size_t end = at + internal_name.size();
        if (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end]))) continue;  // a longer number
        message.replace(at, internal_name.size(), "vertex " + std::to_string(user));
        break;
    }
    return SimulationError(message, e.step(), user);
}
}  // namespace

template <class S>
void OrderedSimulator<S>::push() {
    if (identity()) return;
    require_finite_vectors<S>(u_, "displacement");
    require_finite_vectors<S>(v_, "velocity");
    require_finite_vectors<S>(fext_, "external_forces");
    gather<S, S>(u_, sim_.displacement(), new_of_old_, true);
    gather<S, S>(v_, sim_.velocity(), new_of_old_, true);
    gather<S, S>(fext_, sim_.external_forces(), new_of_old_, true);
}

template <class S>
void OrderedSimulator<S>::pull() {
    if (identity()) return;
    gather<S, S>(sim_.displacement(), u_, new_of_old_, false);
    gather<S, S>(sim_.velocity(), v_, new_of_old_, false);
    gather<S, S>(sim_.forces(), f_, new_of_old_, false);
}

template <class S>
const StepStats& OrderedSimulator<S>::step() {
    const InUseFlag::Claim claim(in_use_, "step");
    push();
    try {
        const StepStats& st = sim_.step();
        pull();
        return st;
    } catch (const SimulationError& e) {
        pull();  // the state before the step (the simulator restored it)
        throw to_user_numbering(e, new_of_old_);
    }
}

template <class S>
StaticResult OrderedSimulator<S>::solve_static(const StaticProgressFn& progress) {
    const InUseFlag::Claim claim(in_use_, "solve_static");
    push();
    try {
        const StaticResult r = sim_.solve_static(progress);
        pull();
        return r;
    } catch (const SimulationError& e) {
        pull();
        throw to_user_numbering(e, new_of_old_);
    }
}

template <class S>
void OrderedSimulator<S>::save_checkpoint(const std::string& path) {
    const InUseFlag::Claim claim(in_use_, "save_checkpoint");
    push();
    sim_.save_checkpoint(path, ordering_);
}

template <class S>
void OrderedSimulator<S>::load_checkpoint(const std::string& path) {
    const InUseFlag::Claim claim(in_use_, "load_checkpoint");
    sim_.load_checkpoint(path, ordering_);
    pull();
    if (!identity()) gather<S, S>(sim_.external_forces(), fext_, new_of_old_, false);
}

template <class S>
Energies OrderedSimulator<S>::energies() {
    const InUseFlag::Claim claim(in_use_, "energies");
    push();
    return sim_.energies();
}

namespace {
template <class From, class To>
void copy_into_user(std::span<const From> view, std::span<To> out) {
    check_length(out.size(), view.size());
    std::copy(view.begin(), view.end(), out.begin());
}
template <class From, class To>
void copy_from_user(std::span<const From> in, std::span<To> view) {
    check_length(in.size(), view.size());
    std::copy(in.begin(), in.end(), view.begin());
}
}  // namespace

template <class S>
void OrderedSimulator<S>::get_displacement(std::span<double> out) const {
    copy_into_user<S, double>(const_cast<OrderedSimulator&>(*this).displacement(), out);
}
template <class S>
void OrderedSimulator<S>::set_displacement(std::span<const double> in) {
    copy_from_user<double, S>(in, displacement());
}
template <class S>
void OrderedSimulator<S>::get_velocity(std::span<double> out) const {
    copy_into_user<S, double>(const_cast<OrderedSimulator&>(*this).velocity(), out);
}
template <class S>
void OrderedSimulator<S>::set_velocity(std::span<const double> in) {
    copy_from_user<double, S>(in, velocity());
}
template <class S>
void OrderedSimulator<S>::get_forces(std::span<double> out) const {
    copy_into_user<S, double>(forces(), out);
}
template <class S>
void OrderedSimulator<S>::set_external_forces(std::span<const double> in) {
    copy_from_user<double, S>(in, external_forces());
}
template <class S>
std::vector<double> OrderedSimulator<S>::positions() const {
    std::vector<double> x(user_scene_.mesh.X);
    const auto u = const_cast<OrderedSimulator&>(*this).displacement();
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += double(u[i]);
    return x;
}

template class OrderedSimulator<double>;
template class OrderedSimulator<float>;

}  // namespace edgefem
