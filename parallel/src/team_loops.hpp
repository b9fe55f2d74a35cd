// What each thread of a team runs for an executor's loops, shared by the
// OpenMP, pool, oneTBB and adaptive executors (a private header of
// parallel/src).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <thread>

#include "edgefem/parallel/executors.hpp"

namespace edgefem::team {

// `threads`, or `all` when threads <= 0; InvalidArgument above kMaxThreads.
int checked_threads(int threads, int all);

// All phases' chunks on the calling thread, in order: what every executor
// does with one thread or nothing to share.
inline void run_phases_here(int phases, const index_t* chunk_first, const std::function<void(int, index_t)>& body) {
    for (int p = 0; p < phases; ++p)
        for (index_t c = 0; c < chunk_first[p + 1] - chunk_first[p]; ++c) body(p, c);
}

// The same for linked phases (`chunks` in every phase).
inline void run_linked_here(int phases, index_t chunks, const std::function<void(int, index_t)>& body) {
    for (int p = 0; p < phases; ++p)
        for (index_t c = 0; c < chunks; ++c) body(p, c);
}

// The most chunks in any phase.
inline index_t widest_phase(int phases, const index_t* chunk_first) {
    index_t widest = 0;
    for (int p = 0; p < phases; ++p) widest = std::max(widest, chunk_first[p + 1] - chunk_first[p]);
    return widest;
}

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
// measured: docs/lab/parallel-log.md, Update 6).
inline void fill_shares(Share* shares, int t, index_t n) {
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

// Every phase's shares for t threads, set up before the team starts, so a
// phase's threads start on it right after the barrier with nothing to reset.
inline std::unique_ptr<Share[]> phase_shares(int t, int phases, const index_t* chunk_first) {
    std::unique_ptr<Share[]> shares(new Share[std::size_t(phases) * std::size_t(t)]);
    for (int p = 0; p < phases; ++p) fill_shares(&shares[std::size_t(p) * t], t, chunk_first[p + 1] - chunk_first[p]);
    return shares;
}

// The static schedule: thread i of team gets the same contiguous chunks at
// every call, dealt as `omp for schedule(static)` deals them (the first
// n % team threads one more), so a thread's share of the data is the same
// in every loop.
inline void static_range(index_t n, int i, int team, index_t& c0, index_t& c1) {
    const index_t q = n / team, r = n % team;
    c0 = i * q + std::min<index_t>(i, r);
    c1 = c0 + q + (i < r);
}

// Spins (pause) until done() holds, yielding after every 4000 spins so that
// an oversubscribed team still makes progress.
template <class Done>
void spin_until(const Done& done) {
    for (int spins = 0; !done();) {
        if (++spins < 4000) {
            __builtin_ia32_pause();
        } else {
            std::this_thread::yield();
            spins = 0;
        }
    }
}

// The barrier between the phases of one team: a counter and a generation,
// spun on. libgomp's barrier ends with a futex_wake system call by the last
// thread to arrive, every time; on a VM with page-table isolation that made
// each phase boundary cost 1.2-1.7 µs, against 0.08-0.10 for this one
// (measured: docs/lab/parallel-log.md, Update 6). A waiter spins, then
// yields, so that an oversubscribed team still makes progress.
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
        spin_until([&] { return generation.load(std::memory_order_acquire) != g; });
    }
};

// Thread i of a team of `team`: every phase's chunks (body(p, c)) of its
// schedule, wait() between phases. `shares` (dynamic only) holds t shares
// per phase (phase_shares); t >= team.
template <class Wait, class Body>
void team_phases(Schedule schedule, int i, int team, int phases, const index_t* chunk_first, Share* shares, int t,
                 Wait&& wait, const Body& body) {
    for (int p = 0; p < phases; ++p) {
        if (p > 0) wait();
        const index_t n = chunk_first[p + 1] - chunk_first[p];
        if (schedule == Schedule::Static) {
            index_t c0, c1;
            static_range(n, i, team, c0, c1);
            for (index_t c = c0; c < c1; ++c) body(p, c);
        } else {
            work_shares(&shares[std::size_t(p) * t], t, i, [&](index_t c) { body(p, c); });
        }
    }
}

// Linked phases (Executor::for_linked_phases): a count of the phases of a
// chunk that have finished, on a cache line of its own (its neighbours spin
// on it). A call counts on from `base`, so counters kept from call to call
// need no reset: base + p once the chunk's phase p - 1 is done.
struct alignas(64) ChunkProgress {
    std::atomic<std::int64_t> done{0};
};

// Thread i of a team of `team`: its static range of the chunks, phase by
// phase. Chunk c of phase p > 0 is ready once the chunks of phase p - 1
// that c needs and that another thread runs have finished (its own ran
// before); the thread runs its chunks of the phase in order, except that
// it takes a later ready one rather than wait for an earlier one (on
// bunny-4k's force at 2 threads, the last part's incoming windows while the
// first's wait for the other thread). Every chunk's count moves on even
// when body skips it (after an exception), so no neighbour waits for ever.
template <class Body>
void team_linked_phases(int i, int team, int phases, index_t chunks, const index_t* need_first,
                        const index_t* need_last, ChunkProgress* progress, std::int64_t base, const Body& body) {
    index_t c0, c1;
    static_range(chunks, i, team, c0, c1);
    const auto ready = [&](int p, index_t c) {
        const std::size_t k = std::size_t(p - 1) * std::size_t(chunks) + std::size_t(c);
        const index_t lo = std::max<index_t>(0, std::min(need_first[k], c));
        const index_t hi = std::min<index_t>(chunks - 1, std::max(need_last[k], c));
        for (index_t d = lo; d <= hi; ++d)
            if ((d < c0 || d >= c1) && progress[d].done.load(std::memory_order_acquire) < base + p) return false;
        return true;
    };
    const auto run = [&](int p, index_t c) {
        body(p, c);
        progress[c].done.store(base + p + 1, std::memory_order_release);
    };
    for (int p = 0; p < phases; ++p) {
        if (p == 0 || c1 - c0 > 64) {  // in order (a range too long for the mask below: wait for each)
            for (index_t c = c0; c < c1; ++c) {
                if (p > 0) spin_until([&] { return ready(p, c); });
                run(p, c);
            }
            continue;
        }
        // Bit j of `left`: chunk c0 + j not run yet in this phase.
        std::uint64_t left = c1 - c0 == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << (c1 - c0)) - 1;
        while (left) {
            index_t pick = -1;
            spin_until([&] {
                for (std::uint64_t l = left; l; l &= l - 1) {
                    const index_t c = c0 + index_t(__builtin_ctzll(l));
                    if (ready(p, c)) {
                        pick = c;
                        return true;
                    }
                }
                return false;
            });
            run(p, pick);
            left &= ~(std::uint64_t(1) << (pick - c0));
        }
    }
}

}  // namespace edgefem::team
