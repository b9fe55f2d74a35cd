#include "edgefem/core/sparse_assembly.hpp"

namespace edgefem {

index_t number_free_dofs(const std::vector<std::uint8_t>& free_dof, std::vector<index_t>& dof_index) {
    dof_index.resize(free_dof.size());
    index_t n = 0;
    for (std::size_t i = 0; i < free_dof.size(); ++i) dof_index[i] = free_dof[i] ? n++ : -1;
    return n;
}

namespace {
template <class S>
struct Collector {
    const std::vector<index_t>* dof;
    double c;
    std::vector<Eigen::Triplet<double>>* out;
    static void visit(void* ctx, index_t a, index_t b, const S* blk) {
        auto* self = static_cast<Collector*>(ctx);
        const auto& dof = *self->dof;
        for (int i = 0; i < 3; ++i) {
            const index_t row = dof[3 * std::size_t(a) + i];
            if (row < 0) continue;
            for (int j = 0; j < 3; ++j) {
                const index_t col = dof[3 * std::size_t(b) + j];
                if (col >= 0) self->out->emplace_back(row, col, self->c * double(blk[3 * i + j]));
            }
        }
    }
};
}  // namespace

template <class S>
Eigen::SparseMatrix<double> assemble_system(const std::vector<index_t>& dof_index, index_t num_free, double c_mass,
                                            const std::vector<double>& mass,
                                            const std::vector<std::pair<double, const ElasticOperator<S>*>>& terms) {
    std::vector<Eigen::Triplet<double>> trip;
    for (std::size_t i = 0; i < dof_index.size(); ++i)
        if (dof_index[i] >= 0 && c_mass != 0) trip.emplace_back(dof_index[i], dof_index[i], c_mass * mass[i / 3]);
    for (const auto& [c, op] : terms) {
        if (c == 0) continue;
        Collector<S> col{&dof_index, c, &trip};
        op->for_each_block(&Collector<S>::visit, &col);
    }
    Eigen::SparseMatrix<double> A(num_free, num_free);
    A.setFromTriplets(trip.begin(), trip.end());  // sums duplicates
    return A;
}

template Eigen::SparseMatrix<double> assemble_system<double>(
    const std::vector<index_t>&, index_t, double, const std::vector<double>&,
    const std::vector<std::pair<double, const ElasticOperator<double>*>>&);
template Eigen::SparseMatrix<double> assemble_system<float>(
    const std::vector<index_t>&, index_t, double, const std::vector<double>&,
    const std::vector<std::pair<double, const ElasticOperator<float>*>>&);

}  // namespace edgefem
