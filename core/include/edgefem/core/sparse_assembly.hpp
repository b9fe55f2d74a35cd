// The assembled path: A = c_m M + sum_k c_k K_k on the free degrees of
// freedom as an Eigen sparse matrix, for the direct solver and for users who
// want the matrix.
#pragma once

#include <Eigen/Sparse>
#include <cstdint>
#include <utility>
#include <vector>

#include "edgefem/core/elastic_operator.hpp"

namespace edgefem {

// dof_index[3v + r]: row of degree of freedom (v, r) among the free ones,
// or -1 when constrained. Returns the number of free dofs.
index_t number_free_dofs(const std::vector<std::uint8_t>& free_dof, std::vector<index_t>& dof_index);

template <class S>
Eigen::SparseMatrix<double> assemble_system(const std::vector<index_t>& dof_index, index_t num_free, double c_mass,
                                            const std::vector<double>& mass,
                                            const std::vector<std::pair<double, const ElasticOperator<S>*>>& terms);

extern template Eigen::SparseMatrix<double> assemble_system<double>(
    const std::vector<index_t>&, index_t, double, const std::vector<double>&,
    const std::vector<std::pair<double, const ElasticOperator<double>*>>&);
extern template Eigen::SparseMatrix<double> assemble_system<float>(
    const std::vector<index_t>&, index_t, double, const std::vector<double>&,
    const std::vector<std::pair<double, const ElasticOperator<float>*>>&);

}  // namespace edgefem
