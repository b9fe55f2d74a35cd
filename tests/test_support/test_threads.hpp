// Thread counts the parallel tests run: 1, 2, 3, 4 and 8 everywhere (more
// threads than the 2 cores of the development machine are fine for
// correctness), plus the hardware's own count when it has more than 8
// (e.g. 16 on a lent many-core machine), so determinism is also checked
// with every thread on its own core.
#pragma once

#include <algorithm>
#include <vector>

#include "edgefem/parallel/executors.hpp"

namespace edgefem::test {

inline const std::vector<int>& test_thread_counts() {
    static const std::vector<int> counts = [] {
        std::vector<int> c{1, 2, 3, 4, 8};
        if (hardware_threads() > 8) c.push_back(hardware_threads());
        return c;
    }();
    return counts;
}

// More threads than cores make OpenMP's barriers slow on larger meshes:
// those runs are kept to meshes of at most `small_tets` tets.
inline bool skip_oversubscribed(long tets, int threads, long small_tets) {
    return tets > small_tets && threads > std::max(2, hardware_threads());
}

}  // namespace edgefem::test
