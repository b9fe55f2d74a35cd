#include "edgefem/core/sparse_cholesky.hpp"

#include <omp.h>
#include <suitesparse/cholmod.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

struct SparseCholesky::Impl {
    cholmod_common c{};
    // The fill-reducing permutation (perm[k]: the row of A at position k of
    // P A P^T) and A's pattern it was found for.
    std::vector<index_t> perm, col_start, row;
    // P A P^T's lower triangle, and where each entry of A goes in it.
    LowerCsc permuted;
    std::vector<index_t> destination;
    cholmod_factor* ll = nullptr;   // supernodal LL^T
    cholmod_factor* ldl = nullptr;  // simplicial LDL^T, analysed when first needed
    // solve()'s buffers, kept between calls (cholmod_solve2 reuses them)
    cholmod_dense* X = nullptr;
    cholmod_dense* Y = nullptr;
    cholmod_dense* E = nullptr;
    std::vector<double> b_permuted;
    bool use_ldl = false;
    bool negative = false;
    int analyses = 0;
    index_t n = 0;

    Impl() {
        cholmod_start(&c);
        c.print = 0;             // status checked here, nothing on stderr
        c.quick_return_if_not_posdef = true;
    }
    ~Impl() {
        free_factors();
        cholmod_free_dense(&X, &c);
        cholmod_free_dense(&Y, &c);
        cholmod_free_dense(&E, &c);
        cholmod_finish(&c);
    }
    void free_factors() {
        if (ll) cholmod_free_factor(&ll, &c);
        if (ldl) cholmod_free_factor(&ldl, &c);
    }

    // A view of a lower-stored matrix as CHOLMOD's symmetric one (no copy).
    static cholmod_sparse view(const LowerCsc& A) {
        cholmod_sparse s{};
        s.nrow = s.ncol = std::size_t(A.n);
        s.nzmax = A.value.size();
        s.p = const_cast<index_t*>(A.col_start.data());
        s.i = const_cast<index_t*>(A.row.data());
        s.x = const_cast<double*>(A.value.data());
        s.stype = -1;
        s.itype = CHOLMOD_INT;
        s.xtype = CHOLMOD_REAL;
        s.dtype = CHOLMOD_DOUBLE;
        s.sorted = 1;
        s.packed = 1;
        return s;
    }

    // A new pattern: the ordering (AMD and METIS nested dissection tried,
    // the one with the least fill kept; on the built-in beam METIS, 12 %
    // fewer flops, docs/solvers.md), then P A P^T's pattern and where each
    // entry of A lands in it. CHOLMOD factorises P A P^T in its natural
    // order, so a factorisation permutes nothing and allocates no copy of
    // A (CHOLMOD itself would transpose A twice per call: 27 % of a
    // bunny-4k step).
    void analyse(const LowerCsc& A) {
        free_factors();
        cholmod_sparse s = view(A);
        c.nmethods = 2;
        c.method[0].ordering = CHOLMOD_AMD;
        c.method[1].ordering = CHOLMOD_METIS;
        c.postorder = true;
        c.supernodal = CHOLMOD_SIMPLICIAL;  // the ordering only: no supernodes needed
        cholmod_factor* order = cholmod_analyze(&s, &c);
        if (!order) throw Error("CHOLMOD: symbolic analysis failed (status " + std::to_string(c.status) + ")");
        const auto* p = static_cast<const index_t*>(order->Perm);
        perm.assign(p, p + A.n);
        cholmod_free_factor(&order, &c);
        std::vector<index_t> position(std::size_t(A.n));
        for (index_t k = 0; k < A.n; ++k) position[std::size_t(perm[std::size_t(k)])] = k;
        // P A P^T's lower entries: column starts by counting, the entries in
        // (column, row) order by one sort
        permuted.n = A.n;
        permuted.col_start.assign(std::size_t(A.n) + 1, 0);
        const std::size_t nnz = A.row.size();
        std::vector<index_t> pr(nnz), pc(nnz);
        for (index_t j = 0; j < A.n; ++j)
            for (index_t e = A.col_start[std::size_t(j)]; e < A.col_start[std::size_t(j) + 1]; ++e) {
                const index_t a = position[std::size_t(A.row[std::size_t(e)])], b = position[std::size_t(j)];
                pr[std::size_t(e)] = std::max(a, b);
                pc[std::size_t(e)] = std::min(a, b);
                ++permuted.col_start[std::size_t(pc[std::size_t(e)]) + 1];
            }
        for (std::size_t j = 0; j < std::size_t(A.n); ++j) permuted.col_start[j + 1] += permuted.col_start[j];
        std::vector<index_t> order_in_column(nnz);
        for (std::size_t e = 0; e < nnz; ++e) order_in_column[e] = index_t(e);
        std::sort(order_in_column.begin(), order_in_column.end(), [&](index_t x, index_t y) {
            return std::pair(pc[std::size_t(x)], pr[std::size_t(x)]) < std::pair(pc[std::size_t(y)], pr[std::size_t(y)]);
        });
        permuted.row.resize(nnz);
        permuted.value.assign(nnz, 0.0);
        destination.resize(nnz);
        for (std::size_t k = 0; k < nnz; ++k) {
            const auto e = std::size_t(order_in_column[k]);
            permuted.row[k] = pr[e];
            destination[e] = index_t(k);
        }
        col_start = A.col_start;
        row = A.row;
        // the supernodal analysis of P A P^T, kept for every factorisation
        ll = analyse_natural(true);
        b_permuted.resize(std::size_t(A.n));
    }

    cholmod_factor* analyse_natural(bool supernodal) {
        cholmod_sparse s = view(permuted);
        c.nmethods = 1;
        c.method[0].ordering = CHOLMOD_NATURAL;
        c.postorder = false;  // perm is already postordered
        c.supernodal = supernodal ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
        cholmod_factor* L = cholmod_analyze(&s, &c);
        if (!L) throw Error("CHOLMOD: symbolic analysis failed (status " + std::to_string(c.status) + ")");
        if (L->ordering != CHOLMOD_NATURAL) throw Error("CHOLMOD: the analysis of P A P^T reordered it");
        ++analyses;
        return L;
    }

    bool factorise(cholmod_factor* L, bool supernodal) {
        cholmod_sparse s = view(permuted);
        c.final_ll = supernodal;
        // CHOLMOD's supernodal factorisation opens an OpenMP region for
        // each supernode's update (four threads, compiled in). With the
        // single-threaded BLAS behind it they only add synchronisation:
        // bunny-4k's direct step 16.6 -> 7.4 ms with them inactive
        // (docs/solvers.md). Inactive for the call, restored after it.
        const int levels = omp_get_max_active_levels();
        omp_set_max_active_levels(0);
        cholmod_factorize(&s, L, &c);
        omp_set_max_active_levels(levels);
        return c.status == CHOLMOD_OK;
    }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::factor(const LowerCsc& A) {
    Impl& m = *impl_;
    if (m.perm.empty() || m.n != A.n || m.col_start != A.col_start || m.row != A.row) m.analyse(A);
    m.n = A.n;
    for (std::size_t e = 0; e < A.value.size(); ++e) m.permuted.value[std::size_t(m.destination[e])] = A.value[e];
    m.negative = false;
    m.use_ldl = false;
    if (m.factorise(m.ll, true)) return true;
    if (m.c.status != CHOLMOD_NOT_POSDEF) return false;
    // Not positive definite: LDL^T without pivoting, as SimplicialLDLT did.
    m.use_ldl = true;
    if (!m.ldl) m.ldl = m.analyse_natural(false);
    if (!m.factorise(m.ldl, false)) return false;
    const cholmod_factor* L = m.ldl;
    const auto* Lp = static_cast<const index_t*>(L->p);
    const auto* Lx = static_cast<const double*>(L->x);
    for (std::size_t j = 0; j < L->n; ++j) {
        const double d = Lx[Lp[j]];
        if (!std::isfinite(d)) return false;
        m.negative = m.negative || d <= 0;
    }
    return true;
}

void SparseCholesky::solve(const double* b, double* x) const {
    Impl& m = *impl_;
    const auto n = std::size_t(m.n);
    for (std::size_t k = 0; k < n; ++k) m.b_permuted[k] = b[std::size_t(m.perm[k])];
    cholmod_dense B{};
    B.nrow = B.d = B.nzmax = n;
    B.ncol = 1;
    B.x = m.b_permuted.data();
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, m.use_ldl ? m.ldl : m.ll, &B, nullptr, &m.X, nullptr, &m.Y, &m.E, &m.c))
        throw Error("CHOLMOD: solve failed (status " + std::to_string(m.c.status) + ")");
    const auto* y = static_cast<const double*>(m.X->x);
    for (std::size_t k = 0; k < n; ++k) x[std::size_t(m.perm[k])] = y[k];
}

bool SparseCholesky::used_ldlt() const { return impl_->use_ldl; }
bool SparseCholesky::indefinite() const { return impl_->negative; }
int SparseCholesky::analyses() const { return impl_->analyses; }

double SparseCholesky::factor_nonzeros() const {
    const cholmod_factor* L = impl_->use_ldl ? impl_->ldl : impl_->ll;
    if (!L) return 0;
    return L->is_super ? double(L->xsize) : double(static_cast<const index_t*>(L->p)[L->n]);
}

}  // namespace edgefem
