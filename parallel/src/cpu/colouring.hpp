// Colourings for the coloured-scatter kernels, computed once per mesh.
//
// Items (edges, TSEP segments, tets) are grouped into units of consecutive
// items: fixed-size blocks of `block` items (block 1: every item is a unit),
// or variable-size ranges given by ColouringOptions::unit_first (for example
// the edges of one METIS part, see part_colouring below). Units are coloured
// so that no two units of one colour write the same target ("resource"), so
// a colour's units can run concurrently with plain (non-atomic) stores, and
// each target is written at most once per colour. Colours run one after
// another in a fixed order, which makes the result independent of the
// thread count.
//
// Greedy first-fit in unit order, then one balancing pass that moves units
// out of over-full colours into the least-used colour they may join
// (Lu et al., "Balanced coloring for parallel computing applications", 2015).
//
// Each colour's units are split into chunks (the unit of work handed to a
// thread) with fixed sizes that depend on the colour's sizes only, never on
// the thread count; chunk ids are global (chunk_first[c] + k) so that a
// kernel can give each chunk its own scratch (the stiffness sink).
#pragma once

#include <algorithm>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "edgefem/core/edge_model.hpp"
#include "cpu/tet_batches.hpp"

namespace edgefem {

struct ColouringStats {
    int colours = 0;
    index_t items = 0;
    index_t block = 1;          // items per unit; 0 for variable-size units (unit_first)
    index_t units = 0;
    index_t min_units = 0;      // smallest colour, in units
    index_t max_units = 0;      // largest colour, in units
    double mean_units = 0;
    index_t min_items = 0;      // smallest colour, in items
    index_t max_items = 0;      // largest colour, in items
    index_t chunks = 0;         // total chunks over all colours
    // "<colours> colours (block <b>), units per colour min/mean/max = ...";
    // variable units: "<colours> colours (<units> units of <mean> items), ...".
    std::string describe() const;
};

struct Colouring {
    index_t num_items = 0;
    index_t block = 1;                  // fixed-size units; 0 when unit_first is used
    std::vector<index_t> unit_first;    // variable units: #units + 1 item offsets; empty: fixed blocks
    std::vector<index_t> colour_first;  // #colours + 1, into units
    std::vector<index_t> units;         // unit ids, ascending within a colour
    std::vector<index_t> chunk_first;   // #colours + 1, global chunk ids
    std::vector<index_t> chunk_units;   // #colours: units per chunk in colour c

    int colours() const { return colour_first.empty() ? 0 : int(colour_first.size() - 1); }
    index_t num_chunks() const { return chunk_first.empty() ? 0 : chunk_first.back(); }
    index_t num_units() const {
        return unit_first.empty() ? (block > 0 ? (num_items + block - 1) / block : 0) : index_t(unit_first.size() - 1);
    }
    // Items of unit u: [unit_first[u], unit_first[u + 1]) with variable
    // units, else [u * block, min(num_items, (u + 1) * block)).
    index_t unit_begin(index_t u) const { return unit_first.empty() ? u * block : unit_first[u]; }
    index_t unit_end(index_t u) const {
        return unit_first.empty() ? std::min(num_items, (u + 1) * block) : unit_first[u + 1];
    }
    ColouringStats stats() const;
};

// Appends the targets item i writes to `out` (duplicates allowed).
using ResourceFn = std::function<void(index_t item, std::vector<index_t>& out)>;

struct ColouringOptions {
    index_t block = 1;        // items per unit (ignored when unit_first is set)
    // Variable-size units: unit u = items [unit_first[u], unit_first[u + 1]);
    // must start at 0, be non-decreasing and end at the number of items
    // (colour_items throws InvalidArgument otherwise). Empty: fixed blocks.
    std::vector<index_t> unit_first;
    bool balance = true;      // run the balancing pass (counts units, not items)
    // Chunking of each colour: about colour_size / chunks_per_colour items
    // per chunk, at least min_chunk_items and at most max_chunk_items items,
    // rounded to whole units (at least one unit; with variable units, by the
    // colour's mean unit size).
    index_t chunks_per_colour = 64;
    index_t min_chunk_items = 16;
    index_t max_chunk_items = 1024;
};

Colouring colour_items(index_t num_items, index_t num_resources, const ResourceFn& resources,
                       const ColouringOptions& opts = {});

// Number of (colour, resource) pairs written by more than one unit of that
// colour: 0 for a valid colouring. Also checks every item appears once.
// Returns -1 when the colouring does not cover the items exactly once
// (every unit once, and with variable units, ranges that tile [0, #items)).
long colouring_conflicts(const Colouring& c, index_t num_resources, const ResourceFn& resources);

// The write sets of the edge kernels' scatter loops (see edge_kernels.hpp).
// Edge scatter (forces, K x, diagonal blocks): V0(E), V1(E).
template <class S>
ResourceFn edge_scatter_resources(const EdgeModel<S>& m);
// Vertex segment a (the edges whose V0 is a, as the segment kernels
// edge_force_segment / edge_kx_segment run them): a and every V1(E).
template <class S>
ResourceFn vertex_segment_resources(const EdgeModel<S>& m);
// TSEP strain segment e0: g(e0) and g(E1) for its TSEPs.
template <class S>
ResourceFn tsep_strain_resources(const EdgeModel<S>& m);
// TSEP stiffness segment e0: K(E2) for the 4 targets of its TSEPs, the sink
// (diagonal targets) excluded: the kernels give each chunk its own sink.
template <class S>
ResourceFn tsep_stiffness_resources(const EdgeModel<S>& m);
// Per-tet scatter: the tet's 4 vertices.
template <class S>
ResourceFn tet_scatter_resources(const TetModel<S>& m);
// Per-tet batch scatter (BatchedTetModel::batches): the 16 vertices of its lanes,
// padding lanes' vertex 0 included (they add zero to it, but a read-modify-
// write all the same).
template <class S>
ResourceFn tet_batch_scatter_resources(const BatchedTetModel<S>& m);

template <class S>
Colouring colour_edges(const EdgeModel<S>& m, const ColouringOptions& opts = {}) {
    return colour_items(m.num_edges(), m.num_vertices, edge_scatter_resources(m), opts);
}
template <class S>
Colouring colour_vertex_segments(const EdgeModel<S>& m, const ColouringOptions& opts = {}) {
    return colour_items(m.num_vertices, m.num_vertices, vertex_segment_resources(m), opts);
}
template <class S>
Colouring colour_tsep_strain(const EdgeModel<S>& m, const ColouringOptions& opts = {}) {
    return colour_items(m.num_edges(), m.num_edges(), tsep_strain_resources(m), opts);
}
template <class S>
Colouring colour_tsep_stiffness(const EdgeModel<S>& m, const ColouringOptions& opts = {}) {
    return colour_items(m.num_edges(), m.num_edges(), tsep_stiffness_resources(m), opts);
}
template <class S>
Colouring colour_tets(const TetModel<S>& m, const ColouringOptions& opts = {}) {
    return colour_items(m.num_tets(), m.num_vertices, tet_scatter_resources(m), opts);
}
template <class S>
Colouring colour_tet_batches(const BatchedTetModel<S>& m, const ColouringOptions& opts = {}) {
    return colour_items(m.num_batches(), m.num_vertices, tet_batch_scatter_resources(m), opts);
}

// Units from vertex parts (partition-aware colouring). item_first[v] ..
// item_first[v + 1] are the items owned by vertex v (#V + 1 offsets, e.g.
// EdgeModel::edge_first or Topology::first_edge: the edges with V0 = v);
// part p is the vertices [part_first[p], part_first[p + 1]) (e.g. the METIS
// parts of vertex_ordering_with_parts in partition/). Returns the item
// offsets of the parts: unit p = the items owned by part p's vertices, a
// contiguous range because items are sorted by owner. Parts that own no
// item are dropped (no empty units).
std::vector<index_t> units_from_vertex_parts(std::span<const index_t> item_first, std::span<const index_t> part_first);

// ColouringOptions whose units are the parts' edge ranges, for the TSEP
// segments (PlanOptions::segment_colouring: TSEP segment e0 is the TSEPs of
// edge e0). `base` supplies the other settings (balancing, chunking); its
// block is ignored.
template <class S>
ColouringOptions part_colouring(const EdgeModel<S>& m, std::span<const index_t> part_first,
                                ColouringOptions base = {}) {
    base.unit_first = units_from_vertex_parts(m.edge_first, part_first);
    return base;
}
// ColouringOptions whose units are the parts themselves (vertex ranges), for
// the vertex segments of the edge scatter (forces, K x, diagonal blocks:
// PlanOptions::vertex_colouring).
inline ColouringOptions part_vertex_colouring(std::span<const index_t> part_first, ColouringOptions base = {}) {
    base.unit_first.assign(part_first.begin(), part_first.end());
    return base;
}

}  // namespace edgefem
