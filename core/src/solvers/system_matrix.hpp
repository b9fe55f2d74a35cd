// A = c_m M + c_k K (+ c_b K0) assembled from the operators' blocks
// (ElasticOperator::for_each_block) into a vertex-block pattern found once:
// K's pattern is the edge graph's and does not change from step to step, so
// later assemblies only add values into known places. The direct solver
// reads its lower triangle on the free dofs, the AMG set-up the whole
// matrix with the constrained rows and columns zero. On the host.
#pragma once

#include <Eigen/SparseCore>

#include "edgefem/core/sparse_cholesky.hpp"
#include "solvers/linear_system.hpp"

namespace edgefem::sim {

template <class S>
class SystemMatrix {
public:
    explicit SystemMatrix(const SimState<S>& state) : s_(state) {}

    // The values for A's current K (the pattern on the first call).
    void assemble(const LinearSystem<S>& A);

    // The lower triangle of A on the free dofs, numbered in dof order.
    const LowerCsc& lower_free() const { return lower_; }
    // A over all 3 #V dofs, rows and columns of constrained dofs zero
    // (stored, so the pattern stays the vertex graph's).
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& projected() const { return projected_; }
    // Whether the free-dof and projected forms are kept up to date.
    void keep(bool lower, bool projected) {
        want_lower_ = lower;
        want_projected_ = projected;
    }
    // Frees the values and the derived forms (the vertex-block pattern
    // stays); the next assemble() makes them again.
    void release();
    // Bytes held (pattern, blocks, the derived forms).
    std::size_t bytes() const;

private:
    void find_pattern(const LinearSystem<S>& A);
    void projected_pattern();

    const SimState<S>& s_;
    bool want_lower_ = true, want_projected_ = false;
    std::vector<index_t> row_start_, col_;  // vertex-block CSR, columns sorted
    std::vector<double> block_;             // 9 per block, row-major
    LowerCsc lower_;
    std::vector<std::size_t> lower_src_;    // lower_.value[e] = block_[lower_src_[e]]
    Eigen::SparseMatrix<double, Eigen::RowMajor> projected_;
};

extern template class SystemMatrix<double>;
extern template class SystemMatrix<float>;

}  // namespace edgefem::sim
