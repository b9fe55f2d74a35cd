// The AMG's matrices kept for the V-cycle: dense rb x cb blocks (a node's
// dofs against a node's or an aggregate's modes: 3 x 6 and 6 x 6 for the
// prolongators, 6 x 6 for the coarse operators), float values and one int
// per block: 4.2-4.4 bytes per entry against 8 for float values with an int
// per entry. The products accumulate in double.
//
// A prolongator P is held grouped one of two ways, with the same blocks:
// by its block rows (fine nodes; the serial V-cycle's) or by its block
// columns (aggregates; the threaded V-cycle's, whose restriction is then a
// gather over coarse rows that threads split). Either way the restriction
// P^T x and the prolongation y + P x add the same terms in the same order,
// so the V-cycle has the same bits on any thread count and stays a fixed
// symmetric operator (P^T reads P's rounded values):
//  - each block's part is a sum over the block's own rows (restriction) or
//    columns (prolongation) of its products, in pairs: ((p0 + p1) + (p2 +
//    p3)) + (p4 + p5) for six, (p0 + p1) + p2 for three;
//  - a coarse entry of P^T x is its blocks' parts added in increasing
//    fine-node order from zero; a fine entry of y + P x is y plus its
//    blocks' parts in increasing aggregate order.
// block_rows.cpp is compiled without floating-point contraction, so that no
// multiply-add is fused in one of those loops and not in its twin.
#pragma once

#include <cstddef>
#include <type_traits>
#include <vector>

#include "edgefem/core/smoothed_aggregation.hpp"

namespace edgefem::amg {

struct BlockRows {
    Eigen::Index rows = 0, cols = 0;
    int rb = 1, cb = 1;           // the blocks' rows and columns
    bool by_columns = false;      // grouped by block column (a prolongator's threaded form)
    // per group (block row, or block column where by_columns), its blocks
    // [start[G], start[G + 1]) and their block columns (block rows)
    std::vector<int> start, col;
    std::vector<float> val;       // rb x cb per block, row-major

    // M's nonzero entries in blocks, grouped by block rows.
    void assign(const SparseRows& M, int row_block, int col_block);
    // The same blocks grouped the other way, in increasing order in each group.
    BlockRows regrouped() const;
    SparseRows expand() const;
    // Drops the blocks whose entries are all zero (assign() stores none).
    void drop_zero_blocks();
    std::size_t bytes() const { return start.size() * sizeof(int) + col.size() * sizeof(int) + val.size() * sizeof(float); }

    // Grouped by rows, y = M x on rows [r0, r1) (whole blocks; the
    // prolongation's order, from zero).
    void times(const double* x, double* y, std::size_t r0, std::size_t r1) const;
};

// coarse = P^T fine: by rows, a scatter over all of P (serial); by columns,
// a gather onto coarse rows [r0, r1) (whole blocks).
void restrict_scatter(const BlockRows& P, const double* fine, double* coarse);
void restrict_gather(const BlockRows& P, const double* fine, double* coarse, std::size_t r0, std::size_t r1);
// fine += P coarse: by rows, a gather onto fine rows [r0, r1) (whole
// blocks); by columns, a scatter over all of P (serial).
void prolong_gather(const BlockRows& P, const double* coarse, double* fine, std::size_t r0, std::size_t r1);
void prolong_scatter(const BlockRows& P, const double* coarse, double* fine);

}  // namespace edgefem::amg
