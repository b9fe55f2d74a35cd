#include "edgefem/partition/ordered_simulator.hpp"

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
template <class From, class To>
void gather(std::span<const From> in, std::span<To> out, const std::vector<index_t>& new_of_old, bool to_internal_order) {
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
