// The threaded kernels' plans: colourings, owner parts, and the tuning
// knobs behind CpuOptions (edgefem/parallel/cpu_backend.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <string_view>

#include "edgefem/parallel/cpu_backend.hpp"
#include "cpu/colouring.hpp"

namespace edgefem {

// Blocks of consecutive items coloured as units: with a locality ordering a
// block is spatially compact, so each thread streams through contiguous
// memory and few colours (barriers) are needed. Measured
// (docs/lab/parallel-log.md, "Which variant is fastest, and why"): one item
// per unit made the colour variant 2-5x slower than serial at 1 thread;
// 1024-item blocks match serial at 1 thread and beat it at 2.
inline ColouringOptions blocked_colouring() {
    ColouringOptions o;
    o.block = 1024;
    o.max_chunk_items = 4096;
    return o;
}

// Vertex segments (the edges sharing their V0, run by the segment kernels
// with V0's sum in registers) in blocks of consecutive vertices. block 0:
// chosen per mesh by the kernels, about #V / 64 vertices (8..128, a function
// of the mesh only), so small meshes still split into enough units.
inline ColouringOptions blocked_vertex_colouring() {
    ColouringOptions o;
    o.block = 0;
    o.max_chunk_items = 512;
    return o;
}

// The owner variant's default part count: a function of the mesh and of
// the machine's hardware thread count, never of the executor's thread count
// (so results are bitwise the same for any thread count on a machine).
//
// The mesh's share: the power of two nearest to cbrt(#V) / 2.5 (in log
// scale), 4..64. A part's spill window spans about the ordering's
// bandwidth, ~#V^(2/3) for a 3D mesh in RCM order, so cbrt(#V) / 2.5 keeps
// the windows near 40 % of a part (measured with RCM: 4 parts on bunny-4k,
// 40 %; 64 parts on bunny-250k, 180 %, phase 2 then cost as much as phase
// 1). A power of two splits evenly over 2, 4, 8 and 16 threads: on this
// 2-core VM (2026-11-22, bench_parallel, medians of 3) armadillo-7k's 5
// parts -> 4 took the 2-thread force from 115 to 86 us, K x from 30.8 to
// 26.3 us and the step from 1.91 to 1.76 ms; box-1200's 3 -> 4 the force
// from 18.3 to 16.2 us and K x from 6.45 to 5.45 us (2 parts were slower
// than 3); bunny-1m's 22 -> 16 the force from 20.4 to 18.1 ms.
//
// The machine's share caps it: the power of two at or above the hardware
// threads, at least 4. Since the parts run their form in tiles (FormTile),
// every part's head costs a pass out of cache, and more parts than the
// threads need lose: bunny-1m at 2 threads (standalone build, 2 runs,
// 2026-11-22 18:20 UTC) force 11.4-12.3 ns/tet with 4 parts against
// 13.6-18.8 with 16, stiffness 31.8-35.3 against 35.0-43.8, K x 4.2-4.4
// against 4.4-6.2; bunny-4k and armadillo-7k (4 parts either way) keep
// theirs. A 16-thread machine keeps 16 parts on bunny-1m.
inline index_t default_owner_parts(index_t num_vertices, int machine_threads) {
    const double x = std::cbrt(double(std::max<index_t>(num_vertices, 1))) / 2.5;
    const int k = std::clamp(int(std::lround(std::log2(std::max(x, 1.0)))), 2, 6);
    index_t machine = 4;
    while (machine < machine_threads && machine < 64) machine *= 2;
    return std::min(index_t(1) << k, machine);
}

// `o` with block 0 replaced by the per-mesh choice for `num_vertices`.
inline ColouringOptions resolved_vertex_colouring(ColouringOptions o, index_t num_vertices) {
    if (o.unit_first.empty() && o.block <= 0) o.block = std::clamp<index_t>(num_vertices / 8, 8, 128);
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
    ColouringOptions vertex_colouring = blocked_vertex_colouring();  // edge scatter by vertex segment (forces, K x, diagonal)
    ColouringOptions segment_colouring = blocked_colouring();  // TSEP segments (g, K)
    ColouringOptions tet_colouring = form_batch_colouring();  // per-tet scatter (items: TetModel::batches; units of 8)
    // FE stiffness from the tet-local form (default) or the TSEP list, and
    // the colouring of the form's batches (kTetLanes tets; units of 8 batches).
    StiffnessLayout stiffness_layout = StiffnessLayout::TetLocal;
    ColouringOptions form_colouring = form_batch_colouring();
    // With the tet-local form, the owner variant's FE forces take g from it
    // too (owner parts of its batches) instead of the TSEP loop: 1.3-1.4x
    // faster at 2 threads on bunny-4k to bunny-1m (measured when the form's
    // forces were added, commit 6a8ef14, 2026-11-22). The
    // colour variant keeps its TSEP segments: the form's batch colouring
    // has more colours, and its barriers lost at 2 threads on armadillo-7k.
    bool form_forces = true;
    index_t range_chunk = 2048;          // items per chunk of the uncoloured loops
    // Owner variant: the number of parts (consecutive vertices for the edge
    // scatter, consecutive edges for the TSEP loop, each balanced on the
    // loop's work). 0: default_owner_parts(#V, hardware_threads()).
    index_t owner_parts = 0;
    // Owner variant with the form: batches per tile of a part's sweep
    // (FormTile). 0: kFormTileBatches.
    index_t form_tile_batches = 0;
    bool stiffness = true;               // build what the stiffness kernels need
};

}  // namespace edgefem
