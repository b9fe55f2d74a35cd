// ElasticOperator::for_each_block for the two stiffness storages every
// back-end keeps on the host: per-edge blocks K(E) = K[V0, V1] (the
// transposed block for K[V1, V0], the diagonal blocks from the operator),
// and per-tet blocks (the 10 distinct blocks a <= b of each tet, the
// transpose for b > a). Used by the back-ends' operators, not by kernels.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "edgefem/core/mesh.hpp"
#include "edgefem/physics/tet_stvk.hpp"

namespace edgefem {


// The transpose of a row-major 3x3 block.
template <class S>
void transpose3(const S* k, S* t) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t[3 * i + j] = k[3 * j + i];
}

// K[V0, V1] and K[V1, V0] of every edge (K: 9 per edge), then the diagonal
// blocks D (9 per vertex).
template <class S, class Visit>
void visit_edge_blocks(const std::vector<std::array<index_t, 2>>& edge, const S* K, const std::vector<S>& D,
                       Visit&& visit) {
    S T[9];
    for (std::size_t e = 0; e < edge.size(); ++e) {
        const S* k = &K[9 * e];
        transpose3(k, T);
        visit(edge[e][0], edge[e][1], k);
        visit(edge[e][1], edge[e][0], static_cast<const S*>(T));
    }
    for (std::size_t v = 0; v < D.size() / 9; ++v) visit(index_t(v), index_t(v), &D[9 * v]);
}

// The diagonal blocks of K from per-tet blocks: D(v) = the sum of the
// blocks (a, a) of the tets at v, in tet order (D: 9 per vertex, overwritten).
template <class S>
void tet_diagonal_blocks(const std::vector<std::array<index_t, 4>>& tet, const S* K, std::size_t num_vertices, S* D) {
    std::fill(D, D + 9 * num_vertices, S(0));
    for (std::size_t t = 0; t < tet.size(); ++t)
        for (int a = 0; a < 4; ++a) {
            const S* blk = &K[90 * t + 9 * physics::tet_block_index(a, a)];
            S* d = &D[9 * std::size_t(tet[t][a])];
            for (int i = 0; i < 9; ++i) d[i] += blk[i];
        }
}

// Every block of every tet (K: 90 per tet, physics::tet_block_index order).
template <class S, class Visit>
void visit_tet_blocks(const std::vector<std::array<index_t, 4>>& tet, const S* K, Visit&& visit) {
    S T[9];
    for (std::size_t t = 0; t < tet.size(); ++t)
        for (int a = 0; a < 4; ++a)
            for (int b = a; b < 4; ++b) {
                const S* blk = &K[90 * t + 9 * physics::tet_block_index(a, b)];
                visit(tet[t][a], tet[t][b], blk);
                if (a == b) continue;
                transpose3(blk, T);
                visit(tet[t][b], tet[t][a], static_cast<const S*>(T));
            }
}

}  // namespace edgefem
