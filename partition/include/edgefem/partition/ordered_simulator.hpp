// A Simulator that runs on a renumbered copy of the scene (for memory
// locality) while the application keeps its own vertex numbering: every
// vertex array in and out is in the user's numbering, and so are the
// vertices that errors name. The views (displacement() ...) are the
// simulator's own user-numbered copies of its state, synchronised with the
// renumbered state around every step(), solve_static() and energies():
// written between calls, they take effect at the next call, as the core
// Simulator's views do. With Ordering::Input (the identity) they are the core
// Simulator's own state and nothing is copied. The core Simulator is
// available through internal(), in the internal numbering.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "edgefem/core/in_use_flag.hpp"
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
    // On any back-end (backend.hpp).
    OrderedSimulator(const Scene& scene, Ordering ordering, std::shared_ptr<const Backend<S>> backend,
                     const OrderingOptions& options = {});

    // A SimulationError names its vertex in the user's numbering (vertex()
    // and the message's "vertex N").
    const StepStats& step();
    StaticResult solve_static(const StaticProgressFn& progress = {});
    Energies energies();
    double time() const { return sim_.time(); }
    long step_index() const { return sim_.step_index(); }
    const StepStats& last_stats() const { return sim_.last_stats(); }
    index_t num_vertices() const { return sim_.num_vertices(); }
    // The scene as given (the user's numbering).
    const Scene& scene() const { return user_scene_; }

    // Views of the state in the user's numbering (3 #V; lumped_mass #V).
    std::span<S> displacement() { return view(u_, &Simulator<S>::displacement); }
    std::span<S> velocity() { return view(v_, &Simulator<S>::velocity); }
    std::span<S> external_forces() { return view(fext_, &Simulator<S>::external_forces); }
    std::span<const S> forces() const { return identity() ? sim_.forces() : std::span<const S>(f_); }
    std::span<const double> lumped_mass() const { return identity() ? sim_.lumped_mass() : std::span<const double>(mass_); }

    // 3 #V values, user numbering; another length throws InvalidArgument.
    void get_displacement(std::span<double> out) const;
    void set_displacement(std::span<const double> in);
    void get_velocity(std::span<double> out) const;
    void set_velocity(std::span<const double> in);
    void get_forces(std::span<double> out) const;
    void set_external_forces(std::span<const double> in);
    std::vector<double> positions() const;

    // Simulator::save_checkpoint / load_checkpoint of the internal
    // simulator, labelled with the ordering: a checkpoint loads only into a
    // simulator with the same ordering (its state is in that numbering).
    void save_checkpoint(const std::string& path);
    void load_checkpoint(const std::string& path);

    Simulator<S>& internal() { return sim_; }
    // Empty for the identity.
    const std::vector<index_t>& new_of_old() const { return new_of_old_; }

private:
    bool identity() const { return new_of_old_.empty(); }
    std::span<S> view(std::vector<S>& mirror, std::span<S> (Simulator<S>::*get)()) {
        return identity() ? (sim_.*get)() : std::span<S>(mirror);
    }
    // The user's views into the internal state (push, after checking that
    // they are finite) and back (pull).
    void push();
    void pull();

    Scene user_scene_;
    std::string ordering_;  // its name: the checkpoints' numbering
    std::vector<index_t> new_of_old_;
    Simulator<S> sim_;
    std::vector<S> u_, v_, fext_, f_;  // the user-numbered views (empty for the identity)
    std::vector<double> mass_;
    InUseFlag in_use_;  // step, solve_static and energies: one thread at a time
};

extern template class OrderedSimulator<double>;
extern template class OrderedSimulator<float>;

}  // namespace edgefem
