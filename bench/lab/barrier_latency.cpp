#include "lab/barrier_latency.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

#include "edgefem/core/error.hpp"

namespace edgefem {

double phase_barrier_us(const Executor& ex, int phases, int repetitions) {
    if (phases < 1) throw InvalidArgument("phase_barrier_us: phases must be >= 1");
    if (repetitions < 1) throw InvalidArgument("phase_barrier_us: repetitions must be >= 1");
    const index_t t = std::max(1, ex.threads());
    std::vector<index_t> first(std::size_t(phases) + 1);
    for (int p = 0; p <= phases; ++p) first[std::size_t(p)] = index_t(p) * t;
    std::vector<double> us;
    for (int r = 0; r < repetitions; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        // Empty bodies: each is still called through the std::function.
        ex.for_uniform_phases(phases, first.data(), [](int, index_t) {});
        us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / phases);
    }
    std::sort(us.begin(), us.end());
    return us[us.size() / 2];
}

}  // namespace edgefem
