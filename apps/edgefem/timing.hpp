// Wall-clock timing of repeated calls for the benchmarking subcommands
// (`bench`, `bench-layouts`, and the evaluators' escape): a warm-up, then
// timed calls, one steady_clock reading each, medians.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <vector>

namespace edgefem::cli {

// At most this many timed calls are kept (32 MiB of durations): a tiny mesh
// runs millions of calls a second, and one double per call would grow without
// bound with --seconds. Past it the timing stops early; the median and
// minimum of 4 million calls are as meaningful as those of more.
inline constexpr std::size_t kMaxTimedCalls = std::size_t(1) << 22;

// Calls `call` for a warm-up (caches, page faults, clock ramp-up: 5% of the
// budget, at least one call), then `warmed_up()`, then timed calls until
// `seconds` have passed and at least `min_calls` calls were timed, or
// `max_calls` calls were timed; returns the timed calls' durations in ns,
// sorted.
template <class Call, class Warm = void (*)()>
std::vector<double> time_calls(double seconds, Call&& call, std::size_t min_calls = 5,
                               std::size_t max_calls = kMaxTimedCalls, Warm&& warmed_up = [] {}) {
    using clock = std::chrono::steady_clock;
    const auto budget = std::chrono::duration<double>(seconds);
    max_calls = std::max(max_calls, min_calls);
    for (const auto w0 = clock::now();;) {
        call();
        if (clock::now() - w0 >= 0.05 * budget) break;
    }
    warmed_up();
    std::vector<double> ns;
    for (const auto start = clock::now();
         ns.size() < min_calls || (ns.size() < max_calls && clock::now() - start < budget);) {
        const auto t0 = clock::now();
        call();
        const auto t1 = clock::now();
        ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
    }
    std::sort(ns.begin(), ns.end());
    return ns;
}

inline double median_of_sorted(const std::vector<double>& v) {
    const std::size_t n = v.size();
    if (n == 0) return 0;
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Tells the compiler that the memory behind p is read, so the stores of a
// timed call cannot be dropped.
inline void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

}  // namespace edgefem::cli
