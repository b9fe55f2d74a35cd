#include "edgefem/parallel/executors.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <omp.h>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>
#include <string>
#include <thread>

#include "edgefem/core/error.hpp"

namespace edgefem {

Backend parse_backend(std::string_view name) {
    if (name == "serial") return Backend::Serial;
    if (name == "omp" || name == "openmp") return Backend::OpenMP;
    if (name == "tbb") return Backend::TBB;
    throw InvalidArgument("unknown backend '" + std::string(name) + "' (expected serial, omp or tbb)");
}

const char* to_string(Backend b) {
    switch (b) {
        case Backend::Serial: return "serial";
        case Backend::OpenMP: return "omp";
        default: return "tbb";
    }
}

Schedule parse_schedule(std::string_view name) {
    if (name == "static") return Schedule::Static;
    if (name == "dynamic") return Schedule::Dynamic;
    throw InvalidArgument("unknown schedule '" + std::string(name) + "' (expected static or dynamic)");
}

const char* to_string(Schedule s) { return s == Schedule::Static ? "static" : "dynamic"; }

int hardware_threads() {
    const unsigned n = std::thread::hardware_concurrency();
    return n > 0 ? int(n) : 1;
}

// ---- OpenMP ---------------------------------------------------------------

namespace {
int checked_threads(int threads, int all) {
    if (threads > kMaxThreads)
        throw InvalidArgument("threads: " + std::to_string(threads) + " is more than the limit of " +
                              std::to_string(kMaxThreads) + " (this machine has " + std::to_string(hardware_threads()) +
                              " hardware threads)");
    return threads > 0 ? threads : all;
}
}  // namespace

// hardware_threads() is asked once, here: it reads /sys (system calls), too
// slow to ask at every call.
OmpExecutor::OmpExecutor(int threads, Schedule schedule)
    : ScheduledExecutor(checked_threads(threads, omp_get_max_threads()), schedule),
      spin_barrier_(threads_ <= hardware_threads()) {}

// Every parallel region has the full team, also when a pass has fewer
// chunks than threads: libgomp keeps its pool only while consecutive
// regions ask for the same team size. Alternating sizes (say 5 owner parts,
// then 8 edge blocks) docks and wakes threads through futexes at every
// region; on a 16-core VM that made an 8-thread force call on armadillo-7k
// 7x slower than at 4 threads. Idle members just pass the barrier.

namespace {

// A thread's share of a loop's chunks: [next, end), taken one at a time
// from the front, by its owner first and by the others once theirs are done.
struct alignas(64) Share {
    std::atomic<index_t> next{0};
    index_t end = 0;
};

// The dynamic schedule: thread i of t starts on the i-th of t contiguous
// shares, then takes what is left of the others'. Chunk grabs stay on the
// thread's own cache line until the shares run out, and each thread works
// on the same chunks from call to call unless the balance needs otherwise.
// `omp for schedule(dynamic, 1)` dealt chunks out round-robin: neighbouring
// chunks on different cores and a different core for a chunk at each call,
// whose data then crossed between the cores (on a VM whose cores sit 0.4 µs
// apart: bunny-50k's 2-thread force 0.41 ms against 0.29-0.30 static;
// docs/parallel.md, Update 6).
void fill_shares(Share* shares, int t, index_t n) {
    for (int i = 0; i < t; ++i) {
        shares[i].next.store(index_t(std::int64_t(n) * i / t), std::memory_order_relaxed);
        shares[i].end = index_t(std::int64_t(n) * (i + 1) / t);
    }
}

template <class Body>
void work_shares(Share* shares, int t, int i, const Body& body) {
    for (int k = 0; k < t; ++k) {
        Share& s = shares[(i + k) % t];
        for (index_t c; (c = s.next.fetch_add(1, std::memory_order_relaxed)) < s.end;) body(c);
    }
}

}  // namespace

void OmpExecutor::chunks(Schedule schedule, index_t n, const std::function<void(index_t)>& body) const {
    if (n <= 0) return;
    if (n == 1 || threads_ == 1) {  // no parallel region for nothing to share
        for (index_t c = 0; c < n; ++c) body(c);
        return;
    }
    const int t = threads_;
    if (schedule == Schedule::Static) {
#pragma omp parallel for num_threads(t) schedule(static)
        for (index_t c = 0; c < n; ++c) body(c);
    } else {
        std::vector<Share> shares(t);
        fill_shares(shares.data(), t, n);
#pragma omp parallel num_threads(t)
        work_shares(shares.data(), t, omp_get_thread_num(), body);
    }
}

namespace {

// The barrier between the phases of one parallel region: a counter and a
// generation, spun on. libgomp's barrier ends with a futex_wake system call
// by the last thread to arrive, every time; on a VM with page-table
// isolation that made each phase boundary cost 1.2-1.7 µs, against
// 0.08-0.10 for this one (docs/parallel.md, Update 6). A waiter spins,
// then yields, so that an oversubscribed team still makes progress; it is
// used only when the team fits the hardware threads (spin_barrier_).
struct alignas(64) PhaseBarrier {
    alignas(64) std::atomic<int> arrived{0};
    alignas(64) std::atomic<int> generation{0};
    void wait(int team) {
        const int g = generation.load(std::memory_order_relaxed);
        if (arrived.fetch_add(1, std::memory_order_acq_rel) == team - 1) {
            arrived.store(0, std::memory_order_relaxed);
            generation.store(g + 1, std::memory_order_release);
            return;
        }
        for (int spins = 0; generation.load(std::memory_order_acquire) == g;) {
            if (++spins < 4000) {
                __builtin_ia32_pause();
            } else {
                std::this_thread::yield();
                spins = 0;
            }
        }
    }
};

}  // namespace

void OmpExecutor::run_phases(Schedule schedule, int phases, const index_t* chunk_first,
                             const std::function<void(int, index_t)>& body) const {
    index_t widest = 0;
    for (int p = 0; p < phases; ++p) widest = std::max(widest, chunk_first[p + 1] - chunk_first[p]);
    if (threads_ == 1 || widest <= 1) {
        for (int p = 0; p < phases; ++p)
            for (index_t c = 0; c < chunk_first[p + 1] - chunk_first[p]; ++c) body(p, c);
        return;
    }
    const int t = threads_;
    const bool spin = spin_barrier_;
    PhaseBarrier barrier;
    // Dynamic: every phase's shares set up front, so a phase's threads start
    // on it right after the barrier, with nothing to reset.
    std::unique_ptr<Share[]> shares;
    if (schedule == Schedule::Dynamic) {
        shares.reset(new Share[std::size_t(phases) * std::size_t(t)]);
        for (int p = 0; p < phases; ++p) fill_shares(&shares[std::size_t(p) * t], t, chunk_first[p + 1] - chunk_first[p]);
    }
#pragma omp parallel num_threads(t)
    {
        const int i = omp_get_thread_num(), team = omp_get_num_threads();
        for (int p = 0; p < phases; ++p) {
            if (p > 0) {
                if (spin) {
                    barrier.wait(team);
                } else {
#pragma omp barrier
                }
            }
            const index_t n = chunk_first[p + 1] - chunk_first[p];
            if (schedule == Schedule::Static) {
                // The same contiguous chunks to thread i at every call, as
                // `omp for schedule(static)` deals them in chunks() (the
                // first n % team threads one more), so that a thread's
                // share of the data is the same in both.
                const index_t q = n / team, r = n % team;
                const index_t c0 = i * q + std::min<index_t>(i, r), c1 = c0 + q + (i < r);
                for (index_t c = c0; c < c1; ++c) body(p, c);
            } else {
                work_shares(&shares[std::size_t(p) * t], t, i, [&](index_t c) { body(p, c); });
            }
        }
    }
}

// ---- TBB --------------------------------------------------------------------

struct TbbExecutor::Impl {
    tbb::task_arena arena;
    explicit Impl(int threads) {
        // TBB runs at most its global limit of threads anyway; asking for
        // more only prints a warning. The chunks (and so the results) do not
        // depend on it.
        arena.initialize(std::min(threads, tbb::info::default_concurrency()));
    }
};

TbbExecutor::TbbExecutor(int threads, Schedule schedule)
    : ScheduledExecutor(checked_threads(threads, tbb::info::default_concurrency()), schedule),
      impl_(std::make_unique<Impl>(threads_)) {}

TbbExecutor::~TbbExecutor() = default;

void TbbExecutor::chunks(Schedule schedule, index_t n, const std::function<void(index_t)>& body) const {
    if (n <= 0) return;
    if (n == 1 || threads_ == 1) {
        for (index_t c = 0; c < n; ++c) body(c);
        return;
    }
    const tbb::blocked_range<index_t> range(0, n, 1);
    const auto run = [&](const tbb::blocked_range<index_t>& r) {
        for (index_t c = r.begin(); c < r.end(); ++c) body(c);
    };
    impl_->arena.execute([&] {
        if (schedule == Schedule::Static)
            tbb::parallel_for(range, run, tbb::static_partitioner());
        else
            tbb::parallel_for(range, run, tbb::simple_partitioner());
    });
}

void TbbExecutor::run_phases(Schedule schedule, int phases, const index_t* chunk_first,
                             const std::function<void(int, index_t)>& body) const {
    if (threads_ == 1) {
        for (int p = 0; p < phases; ++p)
            for (index_t c = 0; c < chunk_first[p + 1] - chunk_first[p]; ++c) body(p, c);
        return;
    }
    impl_->arena.execute([&] {
        for (int p = 0; p < phases; ++p) {
            const index_t n = chunk_first[p + 1] - chunk_first[p];
            const auto run = [&](const tbb::blocked_range<index_t>& r) {
                for (index_t c = r.begin(); c < r.end(); ++c) body(p, c);
            };
            if (n <= 1) {
                if (n == 1) body(p, 0);
            } else if (schedule == Schedule::Static) {
                tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 1), run, tbb::static_partitioner());
            } else {
                tbb::parallel_for(tbb::blocked_range<index_t>(0, n, 1), run, tbb::simple_partitioner());
            }
        }
    });
}

// ---- Factory ------------------------------------------------------------------

std::shared_ptr<const Executor> make_executor(Backend backend, int threads, Schedule schedule) {
    switch (backend) {
        case Backend::Serial: return std::make_shared<SerialExecutor>();
        case Backend::OpenMP: return std::make_shared<OmpExecutor>(threads, schedule);
        default: return std::make_shared<TbbExecutor>(threads, schedule);
    }
}

}  // namespace edgefem
