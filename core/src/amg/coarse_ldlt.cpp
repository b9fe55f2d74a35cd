#include "amg/coarse_ldlt.hpp"

// Eigen's dense LDLT and blocked LLT, inlined here, trip g++ 12's false
// -Wmaybe-uninitialized with AVX-512 (GCC PR 105593) at the point of
// inlining, where a pragma does not reach: core/CMakeLists.txt turns that
// warning off for this file only (its only dense kernels are these two).
#include <Eigen/Dense>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>

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

namespace {
// W doubles, the target's widest vector (8 with AVX-512, 4 with AVX, 2
// otherwise; GCC/Clang vector extensions), loaded unaligned; from floats
// converted.
#if defined(__AVX512F__)
constexpr std::size_t W = 8;
#elif defined(__AVX__)
constexpr std::size_t W = 4;
#else
constexpr std::size_t W = 2;
#endif
using Dv = double __attribute__((vector_size(8 * W)));
constexpr std::size_t kBlock = 8;  // rows (columns of L^T) per block: a multiple of W
inline Dv load_d(const double* p) {
    Dv v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
// One conversion instruction (g++ 12 splits __builtin_convertvector into
// halves and inserts: 10-20 % slower here).
inline Dv load_f(const float* p) {
#if defined(__AVX512F__)
    return Dv(_mm512_cvtps_pd(_mm256_loadu_ps(p)));
#elif defined(__AVX__)
    return Dv(_mm256_cvtps_pd(_mm_loadu_ps(p)));
#elif defined(__SSE2__)
    double two;  // two floats' bytes
    std::memcpy(&two, p, sizeof two);
    return Dv(_mm_cvtps_pd(_mm_castpd_ps(_mm_set_sd(two))));
#else
    using Fv = float __attribute__((vector_size(4 * W)));
    Fv v;
    std::memcpy(&v, p, sizeof v);
    return __builtin_convertvector(v, Dv);
#endif
}
inline double lane_sum(const Dv& a) {  // a fixed order
    double s = 0;
    for (std::size_t k = 0; k < W; ++k) s += a[k];
    return s;
}
}  // namespace

// Both triangular solves go through L in blocks of 8 rows (forward) or 8
// columns of L^T (backward). Left of its diagonal block a block is 8 dot
// products over the same stretch of y (forward) or one pass over y with 8
// multiply-adds per entry (backward): 8 independent sums in registers,
// where a row at a time was one chain of dependent adds (30 -> 16 us on
// bunny-4k's 462-dof level, docs/solvers.md). The diagonal blocks go row
// by row. Every sum has a fixed order: the same bits on every call.
void CoarseLdlt::solve(const double* b, double* x) const {
    double* y = y_.data();
    const auto row = [this](std::size_t i) { return lower_.data() + i * (i - (i > 0)) / 2; };
    // y = L^-1 P b
    for (std::size_t i0 = 0; i0 < n_; i0 += kBlock) {
        const std::size_t rows = std::min(kBlock, n_ - i0);
        double left[kBlock] = {};
        if (rows == kBlock) {  // i0 is a multiple of 8: whole vectors
            const float* r[kBlock];
            Dv acc[kBlock] = {};
            for (std::size_t q = 0; q < kBlock; ++q) r[q] = row(i0 + q);
            for (std::size_t j = 0; j < i0; j += W) {
                const Dv yv = load_d(y + j);
                for (std::size_t q = 0; q < kBlock; ++q) acc[q] += load_f(r[q] + j) * yv;
            }
            for (std::size_t q = 0; q < kBlock; ++q) left[q] = lane_sum(acc[q]);
        } else {
            for (std::size_t q = 0; q < rows; ++q) {
                const float* r = row(i0 + q);
                for (std::size_t j = 0; j < i0; ++j) left[q] += double(r[j]) * y[j];
            }
        }
        for (std::size_t q = 0; q < rows; ++q) {
            const std::size_t i = i0 + q;
            const float* r = row(i);
            double s = left[q];
            for (std::size_t j = i0; j < i; ++j) s += double(r[j]) * y[j];
            y[i] = b[perm_[i]] - s;
        }
    }
    for (std::size_t i = 0; i < n_; ++i) y[i] /= d_[i];
    // L^-T: row j of the packed L is column j of L^T; blocks of columns
    // from the last
    for (std::size_t i1 = n_; i1 > 0;) {
        const std::size_t i0 = ((i1 - 1) / kBlock) * kBlock;
        for (std::size_t j = i1; j-- > i0 + 1;) {  // the block's own triangle
            const float* r = row(j);
            for (std::size_t i = i0; i < j; ++i) y[i] -= double(r[i]) * y[j];
        }
        if (i1 - i0 == kBlock) {
            const float* r[kBlock];
            for (std::size_t q = 0; q < kBlock; ++q) r[q] = row(i0 + q);
            for (std::size_t i = 0; i < i0; i += W) {  // i0 is a multiple of 8
                Dv p[kBlock];
                for (std::size_t q = 0; q < kBlock; ++q) p[q] = load_f(r[q] + i) * y[i0 + q];
                const Dv s = load_d(y + i) - (((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7])));
                std::memcpy(y + i, &s, sizeof s);
            }
        } else {
            for (std::size_t q = i0; q < i1; ++q) {
                const float* r = row(q);
                for (std::size_t i = 0; i < i0; ++i) y[i] -= double(r[i]) * y[q];
            }
        }
        i1 = i0;
    }
    for (std::size_t k = 0; k < n_; ++k) x[perm_[k]] = y[k];
}

std::size_t CoarseLdlt::bytes() const {
    return lower_.size() * sizeof(float) + d_.size() * sizeof(double) + perm_.size() * sizeof(int) +
           y_.size() * sizeof(double);
}

}  // namespace edgefem::amg
