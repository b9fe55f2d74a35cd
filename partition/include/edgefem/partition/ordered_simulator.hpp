// A Simulator that runs on a renumbered copy of the scene (for memory
// locality) while the application keeps its own vertex numbering: every
// vertex array in and out is in the user's numbering (copied through the
// permutation), and so are the vertices that errors name. The core
// Simulator's zero-copy views are available through internal(), in the
// internal numbering.
#pragma once

#include <span>
#include <vector>

#include "edgefem/core/simulator.hpp"
#include "edgefem/partition/ordering.hpp"

namespace edgefem {

// The scene with vertices renumbered by new_of_old (fixed and prescribed
// vertices follow).
Scene permute_scene(const Scene& scene, const std::vector<index_t>& new_of_old);

template <class S>
class OrderedSimulator {
public:
    OrderedSimulator(const Scene& scene, Ordering ordering, std::shared_ptr<const Executor> executor = nullptr,
                     OperatorFactory<S> factory = {}, const OrderingOptions& options = {});

    // A SimulationError names its vertex in the user's numbering (vertex()
    // and the message's "vertex N").
    const StepStats& step();
    StaticResult solve_static();
    Energies energies() { return sim_.energies(); }
    double time() const { return sim_.time(); }

    // 3 #V values, user numbering; another length throws InvalidArgument.
    void get_displacement(std::span<double> out) const;
    void set_displacement(std::span<const double> in);
    void get_velocity(std::span<double> out) const;
    void set_velocity(std::span<const double> in);
    void get_forces(std::span<double> out) const;
    void set_external_forces(std::span<const double> in);
    std::vector<double> positions() const;

    Simulator<S>& internal() { return sim_; }
    const std::vector<index_t>& new_of_old() const { return new_of_old_; }

private:
    std::vector<index_t> new_of_old_;
    Simulator<S> sim_;
};

extern template class OrderedSimulator<double>;
extern template class OrderedSimulator<float>;

}  // namespace edgefem
