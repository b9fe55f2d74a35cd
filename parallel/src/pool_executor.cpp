// PoolExecutor: threads - 1 std::threads and the calling thread, woken by
// an epoch counter they spin on between calls (then sleep on it), each call
// ended by a count of finished threads the caller spins on. No system call
// on the way while the threads are busy: what libgomp spends at every
// region start, region end and barrier (executors.hpp says why it matters).
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "edgefem/parallel/executors.hpp"
#include "team_loops.hpp"

namespace edgefem {

namespace {
// Spins of an idle thread before it sleeps on the epoch (~0.1-0.3 ms).
constexpr int kIdleSpins = 8000;
// The pool whose job this thread is running (nested calls run inline).
thread_local const void* tl_running = nullptr;

// One thread's part of a phased call: run(guarded), where guarded(p, c)
// runs body(p, c) unless a chunk of this call has thrown, so that every
// thread still passes every barrier (or moves every chunk count on); then
// this thread's exception, if any, is rethrown (the pool hands the first
// one to the caller).
template <class Run>
void guarded_part(std::atomic<bool>& failed, const std::function<void(int, index_t)>& body, Run&& run) {
    std::exception_ptr mine;
    run([&](int p, index_t c) {
        if (failed.load(std::memory_order_relaxed)) return;
        try {
            body(p, c);
        } catch (...) {
            failed.store(true, std::memory_order_relaxed);
            if (!mine) mine = std::current_exception();
        }
    });
    if (mine) std::rethrow_exception(mine);
}
}  // namespace

struct PoolExecutor::Impl {
    using Job = std::function<void(int)>;  // thread index -> its part of the call

    explicit Impl(int t) : threads(t), spin(t <= hardware_threads()) {
        workers.reserve(std::size_t(t - 1));
        for (int i = 1; i < t; ++i) workers.emplace_back([this, i] { work(i); });
    }
    ~Impl() {
        {
            std::lock_guard<std::mutex> lock(call);
            quit = true;
            epoch.fetch_add(1, std::memory_order_release);
        }
        epoch.notify_all();
        for (auto& w : workers) w.join();
    }

    void work(int i) {
        std::uint32_t seen = 0;
        for (;;) {
            std::uint32_t e;
            for (int spins = 0; (e = epoch.load(std::memory_order_acquire)) == seen;) {
                if (spin && ++spins < kIdleSpins) {
                    __builtin_ia32_pause();
                } else {
                    epoch.wait(seen, std::memory_order_acquire);
                    spins = 0;
                }
            }
            seen = e;
            if (quit) return;
            run_part(i);
            finished.fetch_add(1, std::memory_order_release);
        }
    }

    // Whether the calling thread is inside one of this pool's calls: a call
    // from there would wait for itself, so it runs on the calling thread.
    bool inside() const { return tl_running == this; }

    void run_part(int i) {
        const void* outer = tl_running;
        tl_running = this;
        try {
            (*job)(i);
        } catch (...) {
            std::lock_guard<std::mutex> lock(error_mutex);
            if (!error) error = std::current_exception();
        }
        tl_running = outer;
    }

    // One call: every thread runs job(i), the caller as thread 0.
    void run(const Job& f) {
        std::lock_guard<std::mutex> lock(call);  // one call at a time
        run_locked(f);
    }

    // One linked-phases call: job(i, progress, base) with the chunks' phase
    // counts, kept from call to call (no per-call allocation or reset).
    template <class LinkedJob>
    void run_linked(index_t chunks, int phases, const LinkedJob& f) {
        std::lock_guard<std::mutex> lock(call);
        if (progress_size < chunks) {
            progress.reset(new team::ChunkProgress[std::size_t(chunks)]);
            progress_size = chunks;
            progress_base = 0;
        }
        const std::int64_t base = progress_base;
        progress_base += phases;
        team::ChunkProgress* pr = progress.get();
        run_locked([&](int i) { f(i, pr, base); });
    }

    void run_locked(const Job& f) {
        job = &f;
        error = nullptr;
        finished.store(0, std::memory_order_relaxed);
        epoch.fetch_add(1, std::memory_order_release);
        epoch.notify_all();  // a system call only when a thread sleeps
        run_part(0);
        team::spin_until([&] { return finished.load(std::memory_order_acquire) == threads - 1; });
        job = nullptr;
        if (error) std::rethrow_exception(error);
    }

    const int threads;
    const bool spin;  // the threads fit the hardware threads: spin while idle
    std::vector<std::thread> workers;
    alignas(64) std::atomic<std::uint32_t> epoch{0};
    alignas(64) std::atomic<int> finished{0};
    const Job* job = nullptr;
    bool quit = false;
    std::mutex call, error_mutex;
    std::exception_ptr error;
    std::unique_ptr<team::ChunkProgress[]> progress;  // linked phases, guarded by `call`
    index_t progress_size = 0;
    std::int64_t progress_base = 0;
};

PoolExecutor::PoolExecutor(int threads, Schedule schedule)
    : ScheduledExecutor(team::checked_threads(threads, hardware_threads()), schedule),
      impl_(threads_ > 1 ? std::make_unique<Impl>(threads_) : nullptr) {}

PoolExecutor::~PoolExecutor() = default;

void PoolExecutor::chunks(Schedule schedule, index_t n, const std::function<void(index_t)>& body) const {
    if (n <= 0) return;
    if (n == 1 || threads_ == 1 || impl_->inside()) {
        for (index_t c = 0; c < n; ++c) body(c);
        return;
    }
    const int t = threads_;
    if (schedule == Schedule::Static) {
        impl_->run([&](int i) {
            index_t c0, c1;
            team::static_range(n, i, t, c0, c1);
            for (index_t c = c0; c < c1; ++c) body(c);
        });
    } else {
        std::vector<team::Share> shares(t);
        team::fill_shares(shares.data(), t, n);
        impl_->run([&](int i) { team::work_shares(shares.data(), t, i, body); });
    }
}

void PoolExecutor::run_phases(Schedule schedule, int phases, const index_t* chunk_first,
                              const std::function<void(int, index_t)>& body) const {
    if (threads_ == 1 || team::widest_phase(phases, chunk_first) <= 1 || impl_->inside())
        return team::run_phases_here(phases, chunk_first, body);
    const int t = threads_;
    team::PhaseBarrier barrier;
    const auto shares = schedule == Schedule::Dynamic ? team::phase_shares(t, phases, chunk_first) : nullptr;
    std::atomic<bool> failed{false};
    impl_->run([&](int i) {
        guarded_part(failed, body, [&](const auto& guarded) {
            team::team_phases(schedule, i, t, phases, chunk_first, shares.get(), t, [&] { barrier.wait(t); }, guarded);
        });
    });
}

void PoolExecutor::for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                                     const std::function<void(int, index_t)>& body) const {
    if (phases <= 0 || chunks <= 0) return;
    if (threads_ == 1 || chunks == 1 || impl_->inside()) return team::run_linked_here(phases, chunks, body);
    const int t = threads_;
    std::atomic<bool> failed{false};
    impl_->run_linked(chunks, phases, [&](int i, team::ChunkProgress* progress, std::int64_t base) {
        guarded_part(failed, body, [&](const auto& guarded) {
            team::team_linked_phases(i, t, phases, chunks, need_first, need_last, progress, base, guarded);
        });
    });
}

}  // namespace edgefem
