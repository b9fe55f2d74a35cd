// The write sets of the edge kernels' scatter loops, derived from the
// Topology rather than the kernel model, for checking colourings
// independently of colouring.hpp's own resource functions.
#pragma once

#include "edgefem/core/topology.hpp"
#include "cpu/colouring.hpp"

namespace edgefem::test {

// Edge scatter (forces, K x, diagonal blocks): V0(E), V1(E).
inline ResourceFn edge_write_set(const Topology& topo) {
    return [&topo](index_t e, std::vector<index_t>& out) {
        out.push_back(topo.edges[e][0]);
        out.push_back(topo.edges[e][1]);
    };
}

// Vertex segment a (the edges whose V0 is a): a and their V1.
inline ResourceFn vertex_segment_write_set(const Topology& topo) {
    return [&topo](index_t a, std::vector<index_t>& out) {
        out.push_back(a);
        for (index_t e = topo.first_edge[a]; e < topo.first_edge[a + 1]; ++e) out.push_back(topo.edges[e][1]);
    };
}

// TSEP strain segment e0: g(e0) and g(E1) of its TSEPs.
inline ResourceFn tsep_strain_write_set(const Topology& topo) {
    return [&topo](index_t e0, std::vector<index_t>& out) {
        out.push_back(e0);
        for (index_t P = topo.first_tsep[e0]; P < topo.first_tsep[e0 + 1]; ++P) out.push_back(topo.tseps[P][1]);
    };
}

// TSEP stiffness segment e0: K(E2) of its TSEPs' non-diagonal targets.
inline ResourceFn tsep_stiffness_write_set(const Topology& topo) {
    return [&topo](index_t e0, std::vector<index_t>& out) {
        for (index_t P = topo.first_tsep[e0]; P < topo.first_tsep[e0 + 1]; ++P)
            for (Target t : topo.tsep_targets[P])
                if (t != kDiagonalTarget) out.push_back(target_edge(t));
    };
}

}  // namespace edgefem::test
