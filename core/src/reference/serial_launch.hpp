// The reference back-end's loops (a Launch, unified/unified_vector_kernels.hpp):
// plain serial loops in index order, the whole range one block, sums as
// one running sum.
#pragma once

#include <cstddef>

namespace edgefem {

struct SerialLaunch {
    template <class Body>
    void each(std::size_t n, Body&& body) const {
        for (std::size_t i = 0; i < n; ++i) body(i);
    }
    template <class Body>
    void each_vertex(std::size_t n, Body&& body) const {
        for (std::size_t v = 0; v < n / 3; ++v) body(v);
    }
    template <class Body>
    void blocks(std::size_t n, Body&& body) const {
        if (n > 0) body(std::size_t(0), n);
    }
    template <class Term>
    double sum(std::size_t n, Term&& term) const {
        return range_sum(0, n, term);
    }
    template <class Term>
    static double range_sum(std::size_t lo, std::size_t hi, Term&& term) {
        double s = 0;
        for (std::size_t i = lo; i < hi; ++i) s += term(i);
        return s;
    }
    template <class R, class Block, class Combine>
    R reduce(std::size_t n, R acc, Block&& block, Combine&& combine) const {
        if (n > 0) combine(acc, block(std::size_t(0), n));
        return acc;
    }
};

}  // namespace edgefem
