#include "solvers/system_matrix.hpp"

#include <algorithm>

namespace edgefem::sim {

namespace {

template <class S>
struct PairCollector {
    std::vector<std::pair<index_t, index_t>>* pairs;
    static void visit(void* ctx, index_t a, index_t b, const S*) {
        static_cast<PairCollector*>(ctx)->pairs->emplace_back(a, b);
    }
};

template <class S>
struct BlockAdder {
    const std::vector<index_t>* row_start;
    const std::vector<index_t>* col;
    double* block;
    double c;
    static void visit(void* ctx, index_t a, index_t b, const S* blk) {
        auto* self = static_cast<BlockAdder*>(ctx);
        const auto first = self->col->begin() + (*self->row_start)[std::size_t(a)];
        const auto last = self->col->begin() + (*self->row_start)[std::size_t(a) + 1];
        const std::size_t k = std::size_t(std::lower_bound(first, last, b) - self->col->begin());
        double* d = self->block + 9 * k;
        for (int i = 0; i < 9; ++i) d[i] += self->c * double(blk[i]);
    }
};

}  // namespace

template <class S>
void SystemMatrix<S>::find_pattern(const LinearSystem<S>& A) {
    const std::size_t nv = s_.mass_host.size();
    std::vector<std::pair<index_t, index_t>> pairs;
    for (index_t v = 0; v < index_t(nv); ++v) pairs.emplace_back(v, v);
    PairCollector<S> pc{&pairs};
    A.K().for_each_block(&PairCollector<S>::visit, &pc);
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    row_start_.assign(nv + 1, 0);
    col_.resize(pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        ++row_start_[std::size_t(pairs[k].first) + 1];
        col_[k] = pairs[k].second;
    }
    for (std::size_t v = 0; v < nv; ++v) row_start_[v + 1] += row_start_[v];

    if (!want_lower_) return;
    // Lower triangle on the free dofs: column j = free dof (a, r) holds the
    // free dofs i >= j of row j (A is symmetric), in increasing order.
    const auto& fr = s_.free_host;
    std::vector<index_t> index(fr.size());
    index_t nf = 0;
    for (std::size_t i = 0; i < fr.size(); ++i) index[i] = fr[i] ? nf++ : -1;
    lower_ = LowerCsc{};
    lower_.n = nf;
    lower_.col_start.push_back(0);
    lower_src_.clear();
    for (std::size_t a = 0; a < nv; ++a)
        for (int r = 0; r < 3; ++r) {
            const index_t j = index[3 * a + std::size_t(r)];
            if (j < 0) continue;
            for (index_t k = row_start_[a]; k < row_start_[a + 1]; ++k)
                for (int c = 0; c < 3; ++c) {
                    const index_t i = index[3 * std::size_t(col_[std::size_t(k)]) + std::size_t(c)];
                    if (i < j) continue;
                    lower_.row.push_back(i);
                    lower_src_.push_back(9 * std::size_t(k) + std::size_t(3 * r + c));
                }
            lower_.col_start.push_back(index_t(lower_.row.size()));
        }
    lower_.value.assign(lower_.row.size(), 0.0);
}

// The projected matrix's pattern: every block's 9 entries.
template <class S>
void SystemMatrix<S>::projected_pattern() {
    const std::size_t nv = s_.mass_host.size();
    const index_t n = index_t(3 * nv);
    projected_.resize(n, n);
    std::vector<int> per_row(static_cast<std::size_t>(n));
    for (std::size_t a = 0; a < nv; ++a)
        for (int r = 0; r < 3; ++r) per_row[3 * a + std::size_t(r)] = 3 * (row_start_[a + 1] - row_start_[a]);
    projected_.reserve(per_row);
    for (std::size_t a = 0; a < nv; ++a)
        for (int r = 0; r < 3; ++r)
            for (index_t k = row_start_[a]; k < row_start_[a + 1]; ++k)
                for (int c = 0; c < 3; ++c)
                    projected_.insert(index_t(3 * a) + r, 3 * col_[std::size_t(k)] + c) = 0.0;
    projected_.makeCompressed();
}

template <class S>
void SystemMatrix<S>::assemble(const LinearSystem<S>& A) {
    if (row_start_.empty()) find_pattern(A);
    block_.assign(9 * col_.size(), 0.0);
    const std::size_t nv = s_.mass_host.size();
    for (std::size_t v = 0; v < nv; ++v) {
        const auto first = col_.begin() + row_start_[v], last = col_.begin() + row_start_[v + 1];
        double* d = &block_[9 * std::size_t(std::lower_bound(first, last, index_t(v)) - col_.begin())];
        for (int i = 0; i < 3; ++i) d[4 * i] += A.c_m() * s_.mass_host[v];
    }
    std::vector<std::pair<double, const ElasticOperator<S>*>> terms{{A.c_k(), &A.K()}};
    if (A.c_b() != 0) terms.emplace_back(A.c_b(), A.K0());
    for (const auto& [c, op] : terms) {
        if (c == 0) continue;
        BlockAdder<S> add{&row_start_, &col_, block_.data(), c};
        op->for_each_block(&BlockAdder<S>::visit, &add);
    }
    if (want_lower_)
        for (std::size_t e = 0; e < lower_src_.size(); ++e) lower_.value[e] = block_[lower_src_[e]];
    if (want_projected_) {
        if (projected_.nonZeros() == 0) projected_pattern();
        const auto& fr = s_.free_host;
        double* val = projected_.valuePtr();
        std::size_t e = 0;
        for (std::size_t a = 0; a < nv; ++a)
            for (int r = 0; r < 3; ++r) {
                const bool fa = fr[3 * a + std::size_t(r)];
                for (index_t k = row_start_[a]; k < row_start_[a + 1]; ++k)
                    for (int c = 0; c < 3; ++c) {
                        const bool fb = fr[3 * std::size_t(col_[std::size_t(k)]) + std::size_t(c)];
                        val[e++] = fa && fb ? block_[9 * std::size_t(k) + std::size_t(3 * r + c)] : 0.0;
                    }
            }
    }
}

template <class S>
void SystemMatrix<S>::release() {
    std::vector<double>().swap(block_);
    projected_ = Eigen::SparseMatrix<double, Eigen::RowMajor>();
}

template <class S>
std::size_t SystemMatrix<S>::bytes() const {
    std::size_t b = sizeof(index_t) * (row_start_.size() + col_.size()) + sizeof(double) * block_.size();
    if (want_lower_)
        b += sizeof(index_t) * (lower_.col_start.size() + lower_.row.size()) +
             (sizeof(double) + sizeof(std::size_t)) * lower_.value.size();
    if (want_projected_)
        b += std::size_t(projected_.nonZeros()) * (sizeof(double) + sizeof(int)) + sizeof(int) * std::size_t(projected_.rows() + 1);
    return b;
}

template class SystemMatrix<double>;
template class SystemMatrix<float>;

}  // namespace edgefem::sim
