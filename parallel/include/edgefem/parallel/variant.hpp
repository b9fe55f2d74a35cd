// How a parallel kernel resolves concurrent writes to one target.
#pragma once

#include <string_view>

#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/parallel/colouring.hpp"

namespace edgefem {

enum class Variant {
    Colour,   // coloured scatter: colours in a fixed order, plain stores (deterministic)
    Gather,   // pull: each target sums its sources via CSR lists (deterministic)
    Atomic,   // scatter with std::atomic_ref fetch_add (order varies run to run)
    Private,  // one accumulator per thread part, then a parallel blocked reduction
};

// "colour" (or "color") | "gather" | "atomic" | "private"; throws InvalidArgument.
Variant parse_variant(std::string_view name);
const char* to_string(Variant v);
// True for the variants whose results are bitwise independent of the thread count.
inline bool is_deterministic(Variant v) { return v == Variant::Colour || v == Variant::Gather; }

// Blocks of consecutive items coloured as units: with a locality ordering a
// block is spatially compact, so each thread streams through contiguous
// memory and few colours (barriers) are needed. Measured (docs/parallel.md):
// one item per unit made the colour variant 2-5x slower than serial at 1
// thread; 1024-item blocks match serial at 1 thread and beat it at 2.
inline ColouringOptions blocked_colouring() {
    ColouringOptions o;
    o.block = 1024;
    o.max_chunk_items = 4096;
    return o;
}

inline ColouringOptions form_batch_colouring() {
    ColouringOptions o;
    o.block = 8;
    o.max_chunk_items = 256;
    o.min_chunk_items = 8;
    return o;
}

struct PlanOptions {
    ColouringOptions edge_colouring = blocked_colouring();     // edge scatter (forces, K x, diagonal)
    ColouringOptions segment_colouring = blocked_colouring();  // TSEP segments (g, K)
    ColouringOptions tet_colouring;      // per-tet scatter
    // FE stiffness from the tet-local form (default) or the TSEP list, and
    // the colouring of the form's 8-tet batches (units of 8 batches).
    StiffnessLayout stiffness_layout = StiffnessLayout::TetLocal;
    ColouringOptions form_colouring = form_batch_colouring();
    index_t range_chunk = 2048;          // items per chunk of the uncoloured loops
    bool stiffness = true;               // build what the stiffness kernels need
};

}  // namespace edgefem
