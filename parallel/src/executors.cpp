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
#include "team_loops.hpp"

namespace edgefem {

ExecutorKind parse_executor_kind(std::string_view name) {
    if (name == "serial") return ExecutorKind::Serial;
    if (name == "omp" || name == "openmp") return ExecutorKind::OpenMP;
    if (name == "tbb") return ExecutorKind::TBB;
    if (name == "pool") return ExecutorKind::Pool;
    throw InvalidArgument("unknown backend '" + std::string(name) + "' (expected serial, omp, tbb or pool)");
}

const char* to_string(ExecutorKind b) {
    switch (b) {
        case ExecutorKind::Serial: return "serial";
        case ExecutorKind::OpenMP: return "omp";
        case ExecutorKind::Pool: return "pool";
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

namespace team {
int checked_threads(int threads, int all) {
    if (threads > kMaxThreads)
        throw InvalidArgument("threads: " + std::to_string(threads) + " is more than the limit of " +
                              std::to_string(kMaxThreads) + " (this machine has " + std::to_string(hardware_threads()) +
                              " hardware threads)");
    return threads > 0 ? threads : all;
}
}  // namespace team

// hardware_threads() is asked once, here: it reads /sys (system calls), too
// slow to ask at every call.
OmpExecutor::OmpExecutor(int threads, Schedule schedule)
    : ScheduledExecutor(team::checked_threads(threads, omp_get_max_threads()), schedule),
      spin_barrier_(threads_ <= hardware_threads()) {}

// Every parallel region has the full team, also when a pass has fewer
// chunks than threads: libgomp keeps its pool only while consecutive
// regions ask for the same team size. Alternating sizes (say 5 owner parts,
// then 8 edge blocks) docks and wakes threads through futexes at every
// region; on a 16-core VM that made an 8-thread force call on armadillo-7k
// 7x slower than at 4 threads. Idle members just pass the barrier.

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
        std::vector<team::Share> shares(t);
        team::fill_shares(shares.data(), t, n);
#pragma omp parallel num_threads(t)
        team::work_shares(shares.data(), t, omp_get_thread_num(), body);
    }
}

void OmpExecutor::run_phases(Schedule schedule, int phases, const index_t* chunk_first,
                             const std::function<void(int, index_t)>& body) const {
    if (threads_ == 1 || team::widest_phase(phases, chunk_first) <= 1)
        return team::run_phases_here(phases, chunk_first, body);
    const int t = threads_;
    const bool spin = spin_barrier_;  // the team fits the hardware threads
    team::PhaseBarrier barrier;
    const auto shares = schedule == Schedule::Dynamic ? team::phase_shares(t, phases, chunk_first) : nullptr;
#pragma omp parallel num_threads(t)
    {
        const int team = omp_get_num_threads();
        team::team_phases(schedule, omp_get_thread_num(), team, phases, chunk_first, shares.get(), t, [&] {
            if (spin) {
                barrier.wait(team);
            } else {
#pragma omp barrier
            }
        }, body);
    }
}

void OmpExecutor::for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                                    const std::function<void(int, index_t)>& body) const {
    if (phases <= 0 || chunks <= 0) return;
    if (threads_ == 1 || chunks == 1) return team::run_linked_here(phases, chunks, body);
    // Zeroed per call: concurrent callers may share this executor.
    const std::unique_ptr<team::ChunkProgress[]> progress(new team::ChunkProgress[std::size_t(chunks)]);
#pragma omp parallel num_threads(threads_)
    team::team_linked_phases(omp_get_thread_num(), omp_get_num_threads(), phases, chunks, need_first, need_last,
                             progress.get(), 0, body);
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
    : ScheduledExecutor(team::checked_threads(threads, tbb::info::default_concurrency()), schedule),
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
    if (threads_ == 1) return team::run_phases_here(phases, chunk_first, body);
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

std::shared_ptr<const Executor> make_executor(ExecutorKind backend, int threads, Schedule schedule) {
    switch (backend) {
        case ExecutorKind::Serial: return std::make_shared<SerialExecutor>();
        case ExecutorKind::OpenMP: return std::make_shared<OmpExecutor>(threads, schedule);
        case ExecutorKind::Pool: return std::make_shared<PoolExecutor>(threads, schedule);
        default: return std::make_shared<TbbExecutor>(threads, schedule);
    }
}

}  // namespace edgefem
