#include "amg/coarse_ldlt.hpp"

// Eigen's dense LDLT and blocked LLT, inlined here, trip g++ 12's false
// -Wmaybe-uninitialized with AVX-512 (GCC PR 105593) at the point of
// inlining, where a pragma does not reach: core/CMakeLists.txt turns that
// warning off for this file only (its only dense kernels are these two).
#include <Eigen/Dense>

#include <cmath>

namespace edgefem::amg {

namespace {

// Dense and symmetric from A's lower triangle; a dof whose row is zero (a
// prolongator column without a mode: a constrained or degenerate
// aggregate) gets a unit diagonal.
Eigen::MatrixXd dense(const SparseRows& A) {
    const Eigen::Index n = A.rows();
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index i = 0; i < n; ++i) {
        bool dead = true;
        for (SparseRows::InnerIterator it(A, i); it; ++it) {
            dead = dead && it.value() == 0;
            if (it.col() <= i) D(i, it.col()) = D(it.col(), i) = it.value();
        }
        if (dead) D(i, i) = 1.0;
    }
    return D;
}

// L's strict lower triangle rounded to float and packed by rows, and D,
// from a factorisation's entries (l(i, j), j < i; d(i)); false on a zero or
// non-finite value. `negative`: D has a negative entry.
template <class LowerAt, class DAt>
bool pack(std::size_t n, LowerAt&& l, DAt&& d, std::vector<float>& lower, std::vector<double>& diag, bool& negative) {
    diag.resize(n);
    negative = false;
    for (std::size_t i = 0; i < n; ++i) {
        diag[i] = d(Eigen::Index(i));
        if (!std::isfinite(diag[i]) || diag[i] == 0) return false;
        negative = negative || diag[i] < 0;
    }
    lower.resize(n * (n - (n > 0)) / 2);
    for (std::size_t i = 1; i < n; ++i)
        for (std::size_t j = 0; j < i; ++j) {
            const double v = l(Eigen::Index(i), Eigen::Index(j));
            if (!std::isfinite(v)) return false;
            lower[i * (i - 1) / 2 + j] = float(v);
        }
    return true;
}

}  // namespace

bool CoarseLdlt::factor(const SparseRows& A) {
    n_ = std::size_t(A.rows());
    const auto n = Eigen::Index(n_);
    y_.resize(n_);
    // A definite operator (the usual case) by Cholesky, blocked (matrix
    // products: 5-10x Eigen's LDLT, which is rank-1 updates), in place;
    // L D L^T with L's unit diagonal and D the squares of the Cholesky
    // factor's, no pivoting (none needed). An indefinite one (Cholesky
    // meets a non-positive pivot) by the pivoted LDL^T.
    {
        Eigen::MatrixXd C = dense(A);
        const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(C);
        if (llt.info() == Eigen::Success) {
            perm_.resize(n_);
            for (std::size_t i = 0; i < n_; ++i) perm_[i] = int(i);
            return pack(
                n_, [&](Eigen::Index i, Eigen::Index j) { return C(i, j) / C(j, j); },
                [&](Eigen::Index i) { return C(i, i) * C(i, i); }, lower_, d_, negative_);
        }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(dense(A));  // C was overwritten
    if (ldlt.info() != Eigen::Success) return false;
    // P A P^T = L D L^T: (P b)_k = b[perm_[k]]
    Eigen::VectorXd iota(n);
    for (Eigen::Index i = 0; i < n; ++i) iota[i] = double(i);
    const Eigen::VectorXd moved = ldlt.transpositionsP() * iota;
    perm_.resize(n_);
    for (std::size_t k = 0; k < n_; ++k) perm_[k] = int(moved[Eigen::Index(k)]);
    const Eigen::MatrixXd& L = ldlt.matrixLDLT();  // L strictly below the diagonal (unit diagonal implied)
    return pack(
        n_, [&](Eigen::Index i, Eigen::Index j) { return L(i, j); }, [&](Eigen::Index i) { return ldlt.vectorD()[i]; },
        lower_, d_, negative_);
}

void CoarseLdlt::solve(const double* b, double* x) const {
    double* y = y_.data();
    // y = L^-1 P b, row by row; each row's sum in four interleaved partial
    // sums (a fixed order: the same bits on every call)
    for (std::size_t i = 0; i < n_; ++i) {
        const float* row = &lower_[i * (i - (i > 0)) / 2];
        double s[4] = {0, 0, 0, 0};
        std::size_t j = 0;
        for (; j + 4 <= i; j += 4)
            for (int q = 0; q < 4; ++q) s[q] += double(row[j + std::size_t(q)]) * y[j + std::size_t(q)];
        for (; j < i; ++j) s[0] += double(row[j]) * y[j];
        y[i] = b[perm_[i]] - ((s[0] + s[1]) + (s[2] + s[3]));
    }
    for (std::size_t i = 0; i < n_; ++i) y[i] /= d_[i];
    // L^-T, column-oriented: row j of the packed L is column j of L^T
    for (std::size_t j = n_; j-- > 1;) {
        const float* row = &lower_[j * (j - 1) / 2];
        const double yj = y[j];
        for (std::size_t i = 0; i < j; ++i) y[i] -= double(row[i]) * yj;
    }
    for (std::size_t k = 0; k < n_; ++k) x[perm_[k]] = y[k];
}

std::size_t CoarseLdlt::bytes() const {
    return lower_.size() * sizeof(float) + d_.size() * sizeof(double) + perm_.size() * sizeof(int) +
           y_.size() * sizeof(double);
}

}  // namespace edgefem::amg
