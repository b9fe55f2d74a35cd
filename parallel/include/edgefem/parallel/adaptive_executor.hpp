// An executor that runs each loop of the simulation on its threads only
// where that is faster than running it on the calling thread.
//
// Why: on a small mesh a parallel loop can cost more in fork, barriers and
// cache-line traffic between cores than it saves. How much more depends on
// the machine: on one 2-core VM a barrier took 0.27 µs and the 2-thread
// step on box-1200 beat the serial one; on another the barrier took 1.5 µs
// (a cache line's round trip between the two cores 0.4-0.5 µs) and the same
// step ran 1.9x slower on 2 threads than on 1 (measured:
// docs/lab/parallel-log.md, Update 6). No fixed size threshold fits both,
// so the choice is measured; docs/parallel.md, "The adaptive executor".
//
// How: every call site (the type of the loop body, which is unique per
// lambda in the source, plus the loop's chunk count and kind) is timed for
// its first 2 x `trials` calls, alternately on the wrapped executor and on
// the calling thread (its chunks in order, as the executors already do for
// a single chunk), keeping each mode's fastest call. All sites start their
// trials together, so each mode is timed with its neighbours in the same
// mode. Once a site has its trials, it runs in the one mode chosen for all
// decided sites: the mode with the smaller sum over them of calls x fastest
// call. One mode for all, not one per site: a mix was never timed, and
// measured slower than both (each switch moves the vectors between the
// cores' caches; measured: docs/lab/parallel-log.md, Update 6).
// The machine may change under a long run (on a shared VM the 2-thread step
// took 1.0 ms in one minute and 1.4 ms in the next): after `retrial`
// calls (2^14 by default), then twice as many, ... (at most 2^22 between
// rounds) every site goes through its trials again.
// Results never depend on the choice: the chunks are the caller's and each
// writes only its own outputs, so the deterministic kernels (owner, colour,
// gather, CG's blocked reductions) give bitwise the same numbers either way,
// as they do for any thread count. threads() is the wrapped executor's, so
// plans (owner parts, colourings) are the same too.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <typeindex>
#include <unordered_map>
#include <vector>

#include "edgefem/core/executor.hpp"

namespace edgefem {

class AdaptiveExecutor final : public Executor {
public:
    // trials >= 1 timed calls per mode per site, retrial >= 1 calls before
    // the second round of trials (InvalidArgument otherwise).
    explicit AdaptiveExecutor(std::shared_ptr<const Executor> inner, int trials = 3,
                              std::int64_t retrial = std::int64_t(1) << 14);

    int threads() const override { return inner_->threads(); }
    const char* name() const override { return inner_->name(); }
    const Executor& inner() const { return *inner_; }

    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override;
    void for_phases(int phases, const index_t* chunk_first,
                    const std::function<void(int, index_t)>& body) const override;
    void for_uniform_chunks(index_t n, const std::function<void(index_t)>& body) const override;
    void for_uniform_phases(int phases, const index_t* chunk_first,
                            const std::function<void(int, index_t)>& body) const override;
    void for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                           const std::function<void(int, index_t)>& body) const override;

    // What was measured and chosen at each call site so far.
    struct Site {
        std::string loop;  // the body's type (demangled), e.g. a lambda's enclosing function
        std::string kind;  // "chunks", "phases", "uniform chunks", "uniform phases", "linked phases"
        index_t chunks = 0;
        int phases = 0;
        std::int64_t calls = 0;
        int rounds = 0;  // rounds of trials completed
        double serial_us = 0, parallel_us = 0;  // fastest timed call of each mode (0: none yet)
        bool decided = false;    // its trials are done
        bool faster_serial = false;  // its fastest serial call beat its fastest on the threads
    };
    std::vector<Site> sites() const;
    // Whether the decided sites run on the calling thread (false before any
    // site is decided).
    bool serial() const;
    // E.g. "serial (3 of 7 loops faster serially; weighted 0.41 ms serial
    // against 0.52 on 2 threads)", for reports.
    std::string summary() const;

private:
    enum class Kind : std::uint8_t { Chunks, Phases, UniformChunks, UniformPhases, LinkedPhases };
    struct Key {
        std::type_index type;
        Kind kind;
        int phases;
        index_t chunks;
        bool operator==(const Key& o) const {
            return type == o.type && kind == o.kind && phases == o.phases && chunks == o.chunks;
        }
    };
    struct KeyHash {
        std::size_t operator()(const Key& k) const;
    };
    struct Stats {
        std::int64_t calls = 0;
        double best[2] = {0, 0};  // [serial, parallel], seconds; 0: not timed yet
        int timed[2] = {0, 0};
        bool decided = false;
        int rounds = 0;
    };
    // The mode of this call (0 serial, 1 parallel) and whether to time it.
    int pick(const Key& key, bool& time) const;
    void record(const Key& key, int mode, double seconds) const;
    // Sums over the decided sites of calls x fastest call, per mode (the lock held).
    void weighted_totals(double (&total)[2], int& decided, int& faster_serial) const;
    template <class Run>
    void dispatch(const Key& key, Run&& run) const;

    std::shared_ptr<const Executor> inner_;
    int trials_;
    mutable std::mutex mutex_;
    mutable std::unordered_map<Key, Stats, KeyHash> stats_;
    mutable int mode_ = 1;  // of the decided sites: 0 serial, 1 parallel
    // Calls of decided sites since the last round of trials, and how many
    // start the next one.
    mutable std::int64_t since_trials_ = 0, next_trials_;
};

// `inner` wrapped in an AdaptiveExecutor when it has more than one thread;
// else `inner` itself (nothing to choose).
std::shared_ptr<const Executor> make_adaptive(std::shared_ptr<const Executor> inner, int trials = 3);

}  // namespace edgefem
