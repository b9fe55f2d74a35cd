// Loop shapes the parallel kernels use on an Executor: fixed-size ranges and
// coloured passes. Chunk boundaries depend on the sizes only, never on the
// thread count.
#pragma once

#include <algorithm>

#include "edgefem/core/executor.hpp"
#include "cpu/colouring.hpp"

namespace edgefem::par {

// body(begin, end) over [0, n) in chunks of `chunk` items.
template <class Body>
void for_range(const Executor& ex, index_t n, index_t chunk, Body&& body) {
    if (n <= 0) return;
    const index_t chunks = (n + chunk - 1) / chunk;
    ex.for_chunks(chunks, [&](index_t c) {
        const index_t b = c * chunk;
        body(b, std::min(n, b + chunk));
    });
}

// Items per chunk of an uncoloured loop over n items: about n / 64 (so small
// meshes still split), between 64 and max_chunk. A function of n only.
inline index_t range_chunk(index_t n, index_t max_chunk) {
    return std::clamp<index_t>((n + 63) / 64, std::min<index_t>(64, max_chunk), max_chunk);
}

// body(item, chunk_id) for every item, colour after colour; within a colour
// the chunks run concurrently (chunk_id is global, see Colouring).
template <class Body>
void for_colours(const Executor& ex, const Colouring& col, Body&& body) {
    ex.for_phases(col.colours(), col.chunk_first.data(), [&](int c, index_t k) {
        const index_t ub = col.colour_first[c], ue = col.colour_first[c + 1];
        const index_t cu = col.chunk_units[c];
        const index_t end = std::min(ue, ub + (k + 1) * cu);
        for (index_t x = ub + k * cu; x < end; ++x) {
            const index_t u = col.units[x];
            const index_t ie = col.unit_end(u);
            for (index_t i = col.unit_begin(u); i < ie; ++i) body(i, col.chunk_first[c] + k);
        }
    });
}

// The private-accumulator split: `parts` contiguous pieces of [0, n).
inline index_t part_begin(index_t n, int parts, int p) { return index_t((long long)(n) * p / parts); }

}  // namespace edgefem::par
