#include "edgefem/partition/ordered_simulator.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/partition/permute_mesh.hpp"

namespace edgefem {

Scene permute_scene(const Scene& scene, const std::vector<index_t>& new_of_old) {
    Scene s = scene;
    s.mesh = permute_mesh(scene.mesh, new_of_old);
    for (index_t& v : s.fixed) v = new_of_old.at(v);
    for (auto& p : s.prescribed) p.vertex = new_of_old.at(p.vertex);
    return s;
}

namespace {
// The user's array must hold 3 values per vertex: checked, as the C API's
// counts are, since a short span would be read or written past its end.
template <class From, class To>
void gather(std::span<const From> in, std::span<To> out, const std::vector<index_t>& new_of_old, bool to_internal_order) {
    const std::size_t n = 3 * new_of_old.size();
    const std::size_t given = to_internal_order ? in.size() : out.size();
    if (given != n)
        throw InvalidArgument("expected 3 x #V = " + std::to_string(n) + " values (one xyz per vertex), got " +
                              std::to_string(given));
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

template <class S>
OrderedSimulator<S>::OrderedSimulator(const Scene& scene, Ordering ordering, std::shared_ptr<const Executor> executor,
                                      OperatorFactory<S> factory, const OrderingOptions& options)
    : new_of_old_((scene.validate(), vertex_ordering(scene.mesh, ordering, options))),
      sim_(permute_scene(scene, new_of_old_), std::move(executor), std::move(factory)) {}

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
const StepStats& OrderedSimulator<S>::step() {
    try {
        return sim_.step();
    } catch (const SimulationError& e) {
        throw to_user_numbering(e, new_of_old_);
    }
}

template <class S>
StaticResult OrderedSimulator<S>::solve_static() {
    try {
        return sim_.solve_static();
    } catch (const SimulationError& e) {
        throw to_user_numbering(e, new_of_old_);
    }
}

template <class S>
void OrderedSimulator<S>::get_displacement(std::span<double> out) const {
    gather<S, double>(const_cast<Simulator<S>&>(sim_).displacement(), out, new_of_old_, false);
}
template <class S>
void OrderedSimulator<S>::set_displacement(std::span<const double> in) {
    gather<double, S>(in, sim_.displacement(), new_of_old_, true);
}
template <class S>
void OrderedSimulator<S>::get_velocity(std::span<double> out) const {
    gather<S, double>(const_cast<Simulator<S>&>(sim_).velocity(), out, new_of_old_, false);
}
template <class S>
void OrderedSimulator<S>::set_velocity(std::span<const double> in) {
    gather<double, S>(in, sim_.velocity(), new_of_old_, true);
}
template <class S>
void OrderedSimulator<S>::get_forces(std::span<double> out) const {
    gather<S, double>(sim_.forces(), out, new_of_old_, false);
}
template <class S>
void OrderedSimulator<S>::set_external_forces(std::span<const double> in) {
    gather<double, S>(in, sim_.external_forces(), new_of_old_, true);
}
template <class S>
std::vector<double> OrderedSimulator<S>::positions() const {
    const std::vector<double> internal = sim_.positions();
    std::vector<double> out(internal.size());
    gather<double, double>(internal, out, new_of_old_, false);
    return out;
}

template class OrderedSimulator<double>;
template class OrderedSimulator<float>;

}  // namespace edgefem
