// The AMG's Galerkin operator P^T A P, numerically, into a block pattern
// found once. A refresh used to form it with Eigen's sparse products: four
// temporaries allocated and freed per level, whose page faults, copies and
// sorting made a refresh of bunny-4k's two levels cost 54-64 ms. Here the
// pattern of P^T A P (in vertex blocks) is found at the first product and
// kept (again only when A brings an entry it does not cover); each product
// then runs block row by block row of A: its row of A P summed into a small
// scratch (A's whole rb x rb blocks at a time where its rows hold whole
// blocks, as the assembled fine level and every Galerkin operator do: one
// look-up per block of P instead of one per entry; entry by entry
// otherwise), then P's blocks of that row times it, each cb x cb block
// formed in registers and added into the pattern's blocks on and above the
// diagonal (block sizes fixed at compile time: the 3x6 and 6x6
// prolongators; a refresh 36-49 % faster than entry by entry with the
// sums into the result, docs/solvers.md); the blocks below are their
// transposes (P^T A P is symmetric for a symmetric A; for a float model's
// A, symmetric to its round-off, this makes the coarse operators exactly
// so). One thread, a fixed order: the same bits for any executor.
#pragma once

#include <cstddef>
#include <vector>

#include "edgefem/core/smoothed_aggregation.hpp"

namespace edgefem::amg {

// A block-row matrix: `block_rows` rows of rb x cb blocks (row-major), the
// blocks of row I at [start[I], start[I + 1]) with block columns col[k].
struct BlockRowsView {
    std::size_t block_rows = 0;
    int rb = 1, cb = 1;
    const int* start = nullptr;
    const int* col = nullptr;
    const float* val = nullptr;
};

class GalerkinProduct {
public:
    // P^T A P for A square and symmetric (its rows and columns in blocks of
    // P.rb, A's order P.block_rows * P.rb; the blocks below the result's
    // diagonal are taken as the transposes of those above) and P of 3 x 6 or
    // 6 x 6 blocks with `coarse_blocks` block columns; every block of the
    // result's pattern is stored whole (zeros included).
    // `out` is overwritten (its storage reused where it is large enough).
    void operator()(const SparseRows& A, const BlockRowsView& P, std::size_t coarse_blocks, SparseRows& out);
    // Bytes it keeps between products (the pattern and the scratch).
    std::size_t bytes() const;

private:
    void find_pattern(const SparseRows& A, const BlockRowsView& P, std::size_t coarse_blocks);
    // The product into `out`; false when A has an entry whose block the
    // pattern does not cover.
    bool multiply(const SparseRows& A, const BlockRowsView& P, SparseRows& out);

    std::vector<int> start_, col_;  // block pattern of P^T A P: block columns of each block row, sorted
    std::vector<int> slot_;         // coarse block -> its place in the scratch row, -1 none
    std::vector<int> cols_;         // the coarse blocks of the current row of A P
    std::vector<double> scratch_;   // the current row of A P: rb x cb per block
};

}  // namespace edgefem::amg
