// The Simulator's views of its state (displacement(), velocity(),
// external_forces(), forces()) for any back-end memory. In host memory a
// view is the vector itself. Otherwise (a GPU) it is a host copy, made when
// the view is first asked for after the state changed; a writable view is
// copied back before the next call that reads the state (sync()). So a step
// copies nothing across the bus unless the application asked for a view.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "edgefem/core/backend_vector.hpp"

namespace edgefem::sim {

template <class S>
class HostViews {
public:
    enum Which { U, V, Fext, F, Count };

    std::span<S> writable(BackendVector<S>& vec, Which which) {
        if (vec.memory().space() == MemorySpace::Host) return vec.host();
        Mirror& m = fetch(vec, which);
        m.dirty = &vec;
        return m.host;
    }
    std::span<const S> readable(const BackendVector<S>& vec, Which which) const {
        if (vec.memory().space() == MemorySpace::Host) return vec.host();
        return fetch(vec, which).host;
    }
    // Before a call that reads the state: the written views back in place.
    void sync() const {
        for (Mirror& m : mirror_)
            if (m.dirty) {
                m.dirty->write(m.host);
                m.dirty = nullptr;
            }
    }
    // After a call that changed the state: the copies are stale.
    void changed() const {
        sync();
        for (Mirror& m : mirror_) m.fresh = false;
    }

private:
    struct Mirror {
        std::vector<S> host;
        bool fresh = false;
        BackendVector<S>* dirty = nullptr;  // written through a view since the copy
    };
    Mirror& fetch(const BackendVector<S>& vec, Which which) const {
        Mirror& m = mirror_[which];
        if (!m.fresh) {
            m.host.resize(vec.size());
            vec.read(m.host);
            m.fresh = true;
        }
        return m;
    }
    mutable std::array<Mirror, Count> mirror_;
};

}  // namespace edgefem::sim
