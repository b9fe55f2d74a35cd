// The AMG's coarsest-level solve: a dense LDL^T with symmetric pivoting
// (Eigen's LDLT) of the level's operator, its unit lower factor kept rounded
// to float and packed by rows (n (n - 1) / 2 entries), D in double. The
// coarsest level of smoothed aggregation is nearly dense (bunny-4k's 462-dof
// level: 99,720 of the 106,953 entries of a dense factor under CHOLMOD's
// fill-reducing ordering), so the dense form stores no index, and float
// halves it: 0.43 MB against CHOLMOD's 0.80 MB there. The preconditioner it
// is part of stays a fixed symmetric operator (L~ D L~^T with the same
// rounded L~ both ways). Indefinite operators (a StVK tangent under
// compression) factor too; a zero or non-finite pivot is a failure.
#pragma once

#include <cstddef>
#include <vector>

#include "edgefem/core/smoothed_aggregation.hpp"

namespace edgefem::amg {

class CoarseLdlt {
public:
    // Factorises A (square, symmetric; only its lower triangle is read).
    // Returns false on a zero or non-finite pivot.
    bool factor(const SparseRows& A);
    // x = A^-1 b (n each; x may not alias b).
    void solve(const double* b, double* x) const;
    std::size_t bytes() const;
    // Whether D has a negative entry: the operator is indefinite.
    bool indefinite() const { return negative_; }

private:
    std::size_t n_ = 0;
    std::vector<int> perm_;      // row k of P A P^T is row perm_[k] of A
    std::vector<float> lower_;   // L's strict lower triangle, row i at i (i - 1) / 2
    std::vector<double> d_;      // D
    mutable std::vector<double> y_;
    bool negative_ = false;
};

}  // namespace edgefem::amg
