// A sparse symmetric factorisation by SuiteSparse CHOLMOD: supernodal LL^T
// when the matrix is positive definite, simplicial LDL^T (no pivoting, like
// Eigen's SimplicialLDLT) when LL^T meets a non-positive pivot. The symbolic
// analysis (fill-reducing ordering, elimination tree, supernodes) is done
// when the pattern is new and reused for every later matrix with the same
// pattern: a simulation's K keeps the edge graph's pattern, so each step and
// Newton iteration only refactorises. CHOLMOD's types stay in the source.
#pragma once

#include <memory>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// The lower triangle of a symmetric n x n matrix in compressed columns,
// rows sorted within each column (col_start: n + 1 entries).
struct LowerCsc {
    index_t n = 0;
    std::vector<index_t> col_start, row;
    std::vector<double> value;
};

class SparseCholesky {
public:
    SparseCholesky();
    ~SparseCholesky();
    SparseCholesky(const SparseCholesky&) = delete;
    SparseCholesky& operator=(const SparseCholesky&) = delete;

    // Factorises A (analysing its pattern first when it differs from the
    // last one). Returns false when the factorisation failed (a zero pivot
    // in LDL^T, or a non-finite value).
    bool factor(const LowerCsc& A);
    // x = A^-1 b (n each); x may alias b.
    void solve(const double* b, double* x) const;
    // Whether the last factorisation had to fall back to LDL^T (A not
    // positive definite), and then whether D has a non-positive entry.
    bool used_ldlt() const;
    bool indefinite() const;
    // Symbolic analyses done so far (LL^T and LDL^T ones counted apart:
    // at most one each per pattern).
    int analyses() const;
    // Entries of the factor L (for the memory figures).
    double factor_nonzeros() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace edgefem
