// Executors that run core's chunked loops on threads: OpenMP (a parallel
// for over the chunks) and oneTBB (a parallel_for inside a task_arena the
// executor owns). Threads are created once (OpenMP's pool, the arena) and
// reused by every call; the thread count is fixed per executor, so each
// Simulator can have its own.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "edgefem/core/executor.hpp"

namespace edgefem {

enum class Backend { Serial, OpenMP, TBB, Pool };

// How chunks are handed to threads. Results never depend on it (chunks are
// fixed by the caller); it only changes load balance and overhead.
enum class Schedule { Static, Dynamic };

// "serial" | "omp" (or "openmp") | "tbb" | "pool"; throws InvalidArgument otherwise.
Backend parse_backend(std::string_view name);
// "serial", "omp", "tbb", "pool".
const char* to_string(Backend b);
Schedule parse_schedule(std::string_view name);  // "static" | "dynamic"
const char* to_string(Schedule s);

// An executor with a schedule: for_chunks / for_phases use it, the uniform
// variants always hand chunks out statically. Subclasses implement the two
// loops for a given schedule.
class ScheduledExecutor : public Executor {
public:
    int threads() const override { return threads_; }
    Schedule schedule() const { return schedule_; }
    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        chunks(schedule_, n, body);
    }
    void for_phases(int phases, const index_t* chunk_first,
                    const std::function<void(int, index_t)>& body) const override {
        run_phases(schedule_, phases, chunk_first, body);
    }
    void for_uniform_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        chunks(Schedule::Static, n, body);
    }
    void for_uniform_phases(int phases, const index_t* chunk_first,
                            const std::function<void(int, index_t)>& body) const override {
        run_phases(Schedule::Static, phases, chunk_first, body);
    }

protected:
    ScheduledExecutor(int threads, Schedule schedule) : threads_(threads), schedule_(schedule) {}
    virtual void chunks(Schedule s, index_t n, const std::function<void(index_t)>& body) const = 0;
    virtual void run_phases(Schedule s, int phases, const index_t* chunk_first,
                            const std::function<void(int, index_t)>& body) const = 0;
    int threads_;
    Schedule schedule_;
};

// The most threads an executor accepts (InvalidArgument above it): OpenMP
// starts as many threads as asked, and 1e5 of them overflowed libgomp's
// stack (a crash, not an error); no shared-memory machine this targets has
// more hardware threads. Oversubscription below it stays allowed (the tests
// run 8 threads on 2 cores).
inline constexpr int kMaxThreads = 1024;

class OmpExecutor final : public ScheduledExecutor {
public:
    // threads <= 0: omp_get_max_threads(); more than kMaxThreads: InvalidArgument.
    explicit OmpExecutor(int threads = 0, Schedule schedule = Schedule::Dynamic);
    const char* name() const override { return "omp"; }
    // Linked phases on the static schedule in one parallel region: a chunk
    // waits only for the chunks it needs, spinning on their phase counts.
    void for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                           const std::function<void(int, index_t)>& body) const override;

private:
    void chunks(Schedule s, index_t n, const std::function<void(index_t)>& body) const override;
    // One parallel region for all phases, a barrier between them: spun on
    // when the team fits the hardware threads (spin_barrier_), else
    // OpenMP's.
    void run_phases(Schedule s, int phases, const index_t* chunk_first,
                    const std::function<void(int, index_t)>& body) const override;
    bool spin_barrier_;
};

class TbbExecutor final : public ScheduledExecutor {
public:
    // threads <= 0: the default concurrency; more than kMaxThreads:
    // InvalidArgument. TBB never runs more threads
    // than its global limit (the hardware threads unless the application
    // raises it with tbb::global_control): a larger count is accepted and
    // splits the work the same way, on fewer threads.
    explicit TbbExecutor(int threads = 0, Schedule schedule = Schedule::Dynamic);
    ~TbbExecutor() override;
    const char* name() const override { return "tbb"; }

private:
    void chunks(Schedule s, index_t n, const std::function<void(index_t)>& body) const override;
    // All phases inside one arena entry, one parallel_for per phase.
    void run_phases(Schedule s, int phases, const index_t* chunk_first,
                    const std::function<void(int, index_t)>& body) const override;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// A pool of threads - 1 std::threads started once, plus the calling thread.
// Between calls the threads spin for a while before they sleep, and the
// phases of a call are separated by a spun-on barrier, so that a call on
// busy threads starts and ends without a system call: libgomp makes one at
// every region start, region end and barrier (futex_wake), which cost
// 1.2-1.7 µs each on a VM with page-table isolation (measured:
// docs/lab/parallel-log.md, Update 6). Threads beyond the hardware threads
// are accepted (they spin less and yield). An exception from a chunk is rethrown by the call once
// every thread has finished (the other chunks of that call may or may not
// have run).
class PoolExecutor final : public ScheduledExecutor {
public:
    // threads <= 0: the hardware threads; more than kMaxThreads: InvalidArgument.
    explicit PoolExecutor(int threads = 0, Schedule schedule = Schedule::Dynamic);
    ~PoolExecutor() override;
    const char* name() const override { return "pool"; }
    // Linked phases on the static schedule: a chunk waits only for the
    // chunks it needs, spinning on their phase counts.
    void for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                           const std::function<void(int, index_t)>& body) const override;

private:
    void chunks(Schedule s, index_t n, const std::function<void(index_t)>& body) const override;
    void run_phases(Schedule s, int phases, const index_t* chunk_first,
                    const std::function<void(int, index_t)>& body) const override;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Serial ignores `threads`.
std::shared_ptr<const Executor> make_executor(Backend backend, int threads = 0,
                                              Schedule schedule = Schedule::Dynamic);

// Number of hardware threads available to this process.
int hardware_threads();

}  // namespace edgefem
