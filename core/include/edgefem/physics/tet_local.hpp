// The local numbering of a tet's vertices and edges that every per-tet
// formula uses: local edge e joins vertices tet_edge_vertex(e, 0) <
// tet_edge_vertex(e, 1) (0-1, 0-2, 0-3, 1-2, 1-3, 2-3); vertex v lies on
// the three local edges vertex_edge(v, i), as their first end
// (vertex_sign = +1, p~ = x(first) - x(second)) or second end (-1).
// Functions rather than tables, so that device code can call them.
#pragma once

#include "edgefem/physics/host_device.hpp"

namespace edgefem::physics {

EDGEFEM_HOST_DEVICE constexpr int tet_edge_vertex(int e, int end) {
    constexpr int t[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    return t[e][end];
}
EDGEFEM_HOST_DEVICE constexpr int vertex_edge(int v, int i) {
    constexpr int t[4][3] = {{0, 1, 2}, {0, 3, 4}, {1, 3, 5}, {2, 4, 5}};
    return t[v][i];
}
EDGEFEM_HOST_DEVICE constexpr int vertex_sign(int v, int i) {
    constexpr int t[4][3] = {{1, 1, 1}, {-1, 1, 1}, {-1, -1, 1}, {-1, -1, -1}};
    return t[v][i];
}

}  // namespace edgefem::physics
