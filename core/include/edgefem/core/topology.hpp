// Mesh topology for the edge-based formulation: unique edges, TSEPs
// (tetrahedron-sharing edge pairs), the stiffness targets of each TSEP, and
// the adjacencies the loops and the gather variants need.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "edgefem/core/csr.hpp"
#include "edgefem/core/mesh.hpp"
#include "edgefem/physics/tet_local.hpp"

namespace edgefem {

// Local edges of a tet (a, b, c, d) = (0, 1, 2, 3), in tet_edges order: the
// numbering of physics/tet_local.hpp as a table for set-up code.
inline constexpr auto kTetEdge = [] {
    std::array<std::array<int, 2>, 6> t{};
    for (int e = 0; e < 6; ++e) t[e] = {physics::tet_edge_vertex(e, 0), physics::tet_edge_vertex(e, 1)};
    return t;
}();
// The 15 local edge pairs of a tet: first the 12 vertex-sharing ones, then the
// 3 opposite ones.
inline constexpr int kTetEdgePair[15][2] = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 2}, {1, 3},
                                            {1, 5}, {2, 4}, {2, 5}, {3, 4}, {3, 5}, {4, 5},
                                            {0, 5}, {1, 4}, {2, 3}};
inline constexpr int kVertexSharingPairs = 12;

// A stiffness target of a TSEP: where the block 2 L(P) p~(E0) p~(E1)^T times
// the sign (-1)^(i+j) lands, for (i, j) in {(0,0), (0,1), (1,0), (1,1)}
// (i: end of E0, j: end of E1). Encoded as (E2 << 1) | transpose, where
// transpose means the block is added transposed to K(E2); kDiagonalTarget
// when both ends are the same vertex (the block lands on a diagonal block,
// which is recovered from translation invariance instead).
using Target = std::int32_t;
inline constexpr Target kDiagonalTarget = -1;
inline constexpr index_t target_edge(Target t) { return t >> 1; }
inline constexpr bool target_transposed(Target t) { return (t & 1) != 0; }
// Sign of target slot k = 2 i + j.
inline constexpr int target_sign(int k) { return (k == 0 || k == 3) ? 1 : -1; }

struct Topology {
    index_t num_vertices = 0;
    index_t num_tets = 0;

    // Edge e: edges[e] = {V0, V1} with V0 < V1, sorted lexicographically.
    std::vector<std::array<index_t, 2>> edges;
    // Edges with V0 = v are edges[first_edge[v] .. first_edge[v+1]).
    std::vector<index_t> first_edge;
    // tet_edges[t][k]: the edge of local edge kTetEdge[k] of tet t.
    std::vector<std::array<index_t, 6>> tet_edges;

    // TSEP p: tseps[p] = {E0, E1} with E0 < E1, sorted lexicographically.
    std::vector<std::array<index_t, 2>> tseps;
    // TSEPs with E0 = e are tseps[first_tsep[e] .. first_tsep[e+1]).
    std::vector<index_t> first_tsep;
    // 1 when the two edges of the TSEP are opposite in their tet, 0 when
    // they share a vertex.
    std::vector<std::uint8_t> tsep_opposite;
    // Stiffness targets, slot k = 2 i + j as described at Target.
    std::vector<std::array<Target, 4>> tsep_targets;

    // vertex -> incident edges (ascending), edge -> TSEPs holding it (ascending).
    Csr vertex_edges;
    Csr edge_tseps;

    index_t num_edges() const { return static_cast<index_t>(edges.size()); }
    index_t num_tseps() const { return static_cast<index_t>(tseps.size()); }
    index_t num_opposite_tseps() const;

    // Edge id of {a, b} (any order), or -1 when it is not an edge.
    index_t find_edge(index_t a, index_t b) const;
    // TSEP id of the edge pair {e0, e1} (any order), or -1.
    index_t find_tsep(index_t e0, index_t e1) const;
};

// Builds the topology in O(n) passes plus sorts of short per-vertex and
// per-edge lists. The mesh must be valid (see validate_mesh).
Topology build_topology(const Mesh& mesh);

}  // namespace edgefem
