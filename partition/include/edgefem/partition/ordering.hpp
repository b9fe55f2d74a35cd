// Vertex orderings for memory locality. Renumbering the vertices is enough:
// build_topology sorts edges by their vertices and TSEPs by their first
// edge, so the edge and TSEP loops then stream in the new vertex order.
// Orderings never change results beyond summation order.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

enum class Ordering {
    Input,             // as read
    Random,            // a seeded shuffle: the worst case
    RCM,               // reverse Cuthill-McKee on the vertex graph
    Morton,            // Z-order curve of the rest positions
    NestedDissection,  // METIS_NodeND
    MetisKway,         // METIS k-way parts sized to fit L2, RCM inside each part
};

// input | random | rcm | morton | nd | metis; throws InvalidArgument otherwise.
Ordering parse_ordering(const std::string& name);
const char* to_string(Ordering o);
std::vector<Ordering> all_orderings();

struct OrderingOptions {
    std::uint64_t seed = 12345;              // Random
    std::size_t part_bytes = 512 * 1024;     // MetisKway: target working set per part
    double bytes_per_vertex = 1200;          // MetisKway: force-kernel data per vertex (model + state)
};

// new_of_old[v] = the new index of vertex v (a permutation of 0..#V-1).
std::vector<index_t> vertex_ordering(const Mesh& mesh, Ordering kind, const OrderingOptions& options = {});

// A vertex ordering together with the parts it numbers contiguously. For
// MetisKway: the METIS k-way parts, part p = the new vertex numbers
// [part_first[p], part_first[p + 1]) (parts in the order the ordering
// visits them, empty parts dropped); every other ordering, and a metis
// ordering of a mesh small enough for one part, gives one part. new_of_old is
// exactly vertex_ordering(mesh, kind, options). Partition-aware colouring
// turns the parts into edge units (units_from_vertex_parts, part_colouring in
// parallel/colouring.hpp).
struct PartitionedOrdering {
    std::vector<index_t> new_of_old;
    std::vector<index_t> part_first;  // #parts + 1 offsets into the new numbering
    index_t num_parts() const { return part_first.empty() ? 0 : static_cast<index_t>(part_first.size() - 1); }
};
PartitionedOrdering vertex_ordering_with_parts(const Mesh& mesh, Ordering kind, const OrderingOptions& options = {});

// The part of every vertex (new numbering) from part_first: out[v] = p for
// part_first[p] <= v < part_first[p + 1].
std::vector<index_t> vertex_parts(const std::vector<index_t>& part_first);

// The vertex graph (vertices adjacent when they share a tet edge) as CSR.
void vertex_graph(const Mesh& mesh, std::vector<index_t>& offsets, std::vector<index_t>& adjacency);

// Locality statistics of an ordering over the vertex graph's edges (a, b):
// mean and max |new(a) - new(b)|, and the share of edges with
// |new(a) - new(b)| <= `window` (64 vertices: 1.5 KB of xyz doubles, a few
// cache lines). Nested dissection numbers separators last, so its mean and
// max are large although most neighbours sit close: `near` is the fairer
// measure across orderings.
struct Bandwidth {
    double mean = 0;
    index_t max = 0;
    double near = 0;
};
Bandwidth ordering_bandwidth(const Mesh& mesh, const std::vector<index_t>& new_of_old, index_t window = 64);

}  // namespace edgefem
