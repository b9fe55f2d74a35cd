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
template <class Term>
double blocked_sum(const Executor& ex, std::size_t n, Term&& term) {
    const std::size_t chunks = (n + kVectorChunk - 1) / kVectorChunk;
    std::vector<double> partial(chunks, 0.0);
    for_blocks(ex, n, [&](std::size_t b, std::size_t e) {
        double s = 0;
        for (std::size_t i = b; i < e; ++i) s += term(i);
        partial[b / kVectorChunk] = s;
    });
    double s = 0;
    for (double p : partial) s += p;
    return s;
}

}  // namespace edgefem
