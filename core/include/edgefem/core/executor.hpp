// How work is spread over threads, as core sees it: independent chunks run
// by an Executor. Core ships only the serial one; parallel/ implements
// OpenMP and TBB executors. Chunks are fixed by the caller (never by the
// thread count), so blocked reductions are bitwise reproducible for any
// number of threads.
#pragma once

#include <algorithm>
#include <functional>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

class Executor {
public:
    virtual ~Executor() = default;
    virtual int threads() const = 0;
    virtual const char* name() const = 0;
    // Calls body(c) once for every c in [0, n), possibly concurrently, and
    // returns when all calls have finished.
    virtual void for_chunks(index_t n, const std::function<void(index_t)>& body) const = 0;
    // Phases one after another (the colours of a coloured scatter): in phase
    // p < phases, body(p, c) for every c in [0, chunk_first[p + 1] -
    // chunk_first[p]), possibly concurrently (offsets, as a Colouring keeps
    // them: no per-call list). Same calls as one for_chunks per phase, which
    // is the default; an executor may run all phases in one parallel region
    // with a barrier between them (a barrier costs less than starting a
    // region).
    virtual void for_phases(int phases, const index_t* chunk_first,
                            const std::function<void(int, index_t)>& body) const {
        for (int p = 0; p < phases; ++p)
            for_chunks(chunk_first[p + 1] - chunk_first[p], [&](index_t c) { body(p, c); });
    }
    // The same for chunks of equal work (the fixed blocks of the vector
    // operations): an executor may hand them out statically, the same
    // chunks to the same threads at every call, so that each thread's share
    // of the vectors stays in its own cache from one CG pass to the next.
    virtual void for_uniform_chunks(index_t n, const std::function<void(index_t)>& body) const {
        for_chunks(n, body);
    }
    virtual void for_uniform_phases(int phases, const index_t* chunk_first,
                                    const std::function<void(int, index_t)>& body) const {
        for_phases(phases, chunk_first, body);
    }
    // Phases over the same `chunks` chunks (the fixed parts of an owner
    // scatter), where chunk c of phase p > 0 reads only what chunk c and
    // chunks need_first[k] .. need_last[k] (k = (p - 1) * chunks + c) wrote
    // in phase p - 1 and, through them, in the phases before. An executor
    // may start it as soon as those have finished instead of waiting for
    // the whole phase: no barrier, so one part's slow phase is not every
    // part's wait. The caller must then also make sure that no chunk writes
    // what a chunk of another phase, running at the same time, reads. Same
    // calls as for_uniform_phases, which is the default (barriers satisfy
    // every link).
    virtual void for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                                   const std::function<void(int, index_t)>& body) const {
        (void)need_first;
        (void)need_last;
        std::vector<index_t> first(std::size_t(std::max(phases, 0)) + 1);
        for (std::size_t p = 0; p < first.size(); ++p) first[p] = index_t(p) * chunks;
        for_uniform_phases(phases, first.data(), body);
    }
};

class SerialExecutor final : public Executor {
public:
    int threads() const override { return 1; }
    const char* name() const override { return "serial"; }
    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        for (index_t c = 0; c < n; ++c) body(c);
    }
};

// Elements per block of the blocked vector operations. Fixed, so blocked
// sums are the same for any thread count; a multiple of 3 (a block of dofs
// holds whole vertices) and of 8 (the 8-lane sums). Small, so that a
// cache-resident mesh's vectors split evenly over the threads: with 8192 a
// step's CG vector work on armadillo-7k (6558 dofs) ran on one thread, and
// with 1536 bunny-4k's 3 blocks split 2:1. The blocks are handed out in
// groups (block_groups), so a large mesh does not pay one scheduling step
// per block.
inline constexpr std::size_t kVectorBlock = 384;

inline std::size_t vector_blocks(std::size_t n) { return (n + kVectorBlock - 1) / kVectorBlock; }

// Fewer blocks than this run as one group, on the calling thread: below
// ~512 vertices a parallel region costs more than the pass (box-1200's 3
// blocks: a step at 2 threads 0.249 -> 0.265 ms with them split).
inline constexpr std::size_t kMinParallelBlocks = 4;

// Groups of consecutive blocks, a few per thread (dynamic schedules
// balance them). The grouping depends on the thread count; the blocks, and
// so the results, do not.
inline index_t block_groups(const Executor& ex, std::size_t blocks) {
    if (blocks < kMinParallelBlocks) return static_cast<index_t>(std::min<std::size_t>(blocks, 1));
    return static_cast<index_t>(std::min<std::size_t>(blocks, 4 * std::size_t(std::max(1, ex.threads()))));
}

// body(begin, end) for every block of group g of `groups` over [0, n).
template <class Body>
void for_group_blocks(index_t g, index_t groups, std::size_t n, Body&& body) {
    const std::size_t nb = vector_blocks(n);
    const std::size_t k0 = nb * std::size_t(g) / std::size_t(groups), k1 = nb * std::size_t(g + 1) / std::size_t(groups);
    for (std::size_t k = k0; k < k1; ++k) body(k * kVectorBlock, std::min(n, (k + 1) * kVectorBlock));
}

// body(begin, end) over [0, n) in kVectorBlock blocks.
template <class Body>
void for_blocks(const Executor& ex, std::size_t n, Body&& body) {
    const index_t groups = block_groups(ex, vector_blocks(n));
    ex.for_uniform_chunks(groups, [&](index_t g) { for_group_blocks(g, groups, n, body); });
}

// for_blocks on `ex` when it has more than one thread; else (null or one
// thread) body(0, n) once on the calling thread, for host code whose
// executor is optional.
template <class Body>
void for_blocks_if_threaded(const Executor* ex, std::size_t n, Body&& body) {
    if (!ex || ex->threads() <= 1) return body(std::size_t(0), n);
    for_blocks(*ex, n, body);
}

// Sum of term(i) over one block [b, e): 8 interleaved accumulators combined
// pairwise. A single running sum waits one add latency per term (a CG dot
// product over armadillo-7k took 12% of a semi-implicit step), 8 of them
// vectorise. The order depends on b and e only.
template <class Term>
double block_sum(std::size_t b, std::size_t e, Term&& term) {
    // Vector types spelled out: with a plain a[8] g++ 12 vectorises the
    // outer loop instead and shuffles every term.
    typedef double V4 __attribute__((vector_size(32)));
    V4 s0 = {0, 0, 0, 0}, s1 = {0, 0, 0, 0};
    std::size_t i = b;
    for (; i + 8 <= e; i += 8) {
        s0 += V4{term(i), term(i + 1), term(i + 2), term(i + 3)};
        s1 += V4{term(i + 4), term(i + 5), term(i + 6), term(i + 7)};
    }
    double tail = 0;
    for (; i < e; ++i) tail += term(i);
    const V4 s = s0 + s1;
    return ((s[0] + s[1]) + (s[2] + s[3])) + tail;
}

// The sum of the per-block partials part[0, n), in an order fixed by n
// (block_sum's). A running sum waits one add latency per partial: bunny-1m's
// CG has ~7,800 blocks, and every group of every thread sums them twice an
// iteration.
inline double partials_total(const double* part, std::size_t n) {
    return block_sum(0, n, [part](std::size_t k) { return part[k]; });
}

// Sum over [0, n) of term(i): per-block partial sums (block_sum), added by
// partials_total. The order depends on n only, so the sum is the same for
// any thread count.
template <class Term>
double blocked_sum(const Executor& ex, std::size_t n, Term&& term) {
    std::vector<double> partial(vector_blocks(n), 0.0);
    for_blocks(ex, n, [&](std::size_t b, std::size_t e) { partial[b / kVectorBlock] = block_sum(b, e, term); });
    return partials_total(partial.data(), partial.size());
}

}  // namespace edgefem
