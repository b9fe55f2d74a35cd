// The CPU back-end's loops (a Launch, unified/unified_vector_kernels.hpp):
// fixed blocks of kVectorBlock dofs on an Executor (executor.hpp), sums
// per block combined in block order, so that results are the same for any
// thread count.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "edgefem/core/executor.hpp"

namespace edgefem {

struct BlockedLaunch {
    std::shared_ptr<const Executor> ex;

    template <class Body>
    void each(std::size_t n, Body&& body) const {
        for_blocks(*ex, n, [&](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) body(i);
        });
    }
    // Blocks of dofs hold whole vertices (kVectorBlock is a multiple of 3):
    // blocks of kVectorBlock vertices left bunny-4k's 1141 vertices 3
    // blocks, too few to share, and its preconditioner on one thread.
    template <class Body>
    void each_vertex(std::size_t n, Body&& body) const {
        for_blocks(*ex, n, [&](std::size_t lo, std::size_t hi) {
            for (std::size_t v = lo / 3; v < hi / 3; ++v) body(v);
        });
    }
    template <class Body>
    void blocks(std::size_t n, Body&& body) const {
        for_blocks(*ex, n, body);
    }
    template <class Term>
    double sum(std::size_t n, Term&& term) const {
        return blocked_sum(*ex, n, term);
    }
    template <class Term>
    static double range_sum(std::size_t lo, std::size_t hi, Term&& term) {
        return block_sum(lo, hi, term);
    }
    template <class R, class Block, class Combine>
    R reduce(std::size_t n, R acc, Block&& block, Combine&& combine) const {
        std::vector<R> part(vector_blocks(n));
        for_blocks(*ex, n, [&](std::size_t lo, std::size_t hi) { part[lo / kVectorBlock] = block(lo, hi); });
        for (const R& p : part) combine(acc, p);
        return acc;
    }
};

}  // namespace edgefem
