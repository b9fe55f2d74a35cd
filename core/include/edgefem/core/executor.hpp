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
};

class SerialExecutor final : public Executor {
public:
    int threads() const override { return 1; }
    const char* name() const override { return "serial"; }
    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        for (index_t c = 0; c < n; ++c) body(c);
    }
};

// Elements per chunk of the blocked vector operations (fixed: results do not
// depend on the thread count).
inline constexpr std::size_t kVectorChunk = 8192;

// body(begin, end) over [0, n) in kVectorChunk blocks.
template <class Body>
void for_blocks(const Executor& ex, std::size_t n, Body&& body) {
    const index_t chunks = static_cast<index_t>((n + kVectorChunk - 1) / kVectorChunk);
    ex.for_chunks(chunks, [&](index_t c) {
        const std::size_t b = std::size_t(c) * kVectorChunk;
        body(b, std::min(n, b + kVectorChunk));
    });
}

// Sum over [0, n) of term(i): per-block partial sums, added in block order.
// Inside a block, 8 interleaved accumulators combined pairwise: a single
// running sum waits one add latency per term (a CG dot product over
// armadillo-7k took 12% of a semi-implicit step), 8 of them vectorise. The
// order depends on n only, so the sum is the same for any thread count.
template <class Term>
double blocked_sum(const Executor& ex, std::size_t n, Term&& term) {
    const std::size_t chunks = (n + kVectorChunk - 1) / kVectorChunk;
    std::vector<double> partial(chunks, 0.0);
    for_blocks(ex, n, [&](std::size_t b, std::size_t e) {
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
        partial[b / kVectorChunk] = ((s[0] + s[1]) + (s[2] + s[3])) + tail;
    });
    double s = 0;
    for (double p : partial) s += p;
    return s;
}

}  // namespace edgefem
