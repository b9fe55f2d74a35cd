// The assembled path: A on the free dofs (SystemMatrix, its pattern found
// once), factorised by CHOLMOD (SparseCholesky): supernodal LL^T, or LDL^T
// when A is not positive definite; the symbolic analysis is done once per
// pattern and reused by every later step and Newton iteration. On the host:
// b and x through host() (back-ends with host memory).
#include <cmath>

#include "edgefem/core/sparse_cholesky.hpp"
#include "solvers/system_matrix.hpp"
#include "solvers/system_solver.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class DirectSolver final : public SystemSolver<S> {
public:
    explicit DirectSolver(const SimState<S>& state) : s_(state), matrix_(state) {}

    bool reusable() const override { return false; }
    int analyses() const override { return chol_.analyses(); }

    void setup(LinearSystem<S>& A) override {
        matrix_.assemble(A);
        factored_ = matrix_.lower_free().n == 0 || chol_.factor(matrix_.lower_free());
    }

    CgResult solve(LinearSystem<S>& A, BackendVector<double>& b_vec, BackendVector<double>& x_vec, double, int,
                   const double*) override {
        CgResult res;
        const std::size_t n = s_.n();
        const std::span<const double> b = b_vec.host();
        const std::span<double> x = x_vec.host();
        const auto& free_dof = s_.free_host;
        const LowerCsc& L = matrix_.lower_free();
        if (!factored_) {
            res.residual = INFINITY;
            return res;
        }
        // rhs = b - A x_constrained
        BackendVector<double> xc_vec = s_.template vector<double>(n), Ac_vec = s_.template vector<double>(n);
        const std::span<double> xc = xc_vec.host(), Ac = Ac_vec.host();
        for (std::size_t i = 0; i < n; ++i) xc[i] = free_dof[i] ? 0.0 : x[i];
        A.apply(xc.data(), Ac.data());
        std::vector<double> rhs, sol(std::size_t(L.n));
        for (std::size_t i = 0; i < n; ++i)
            if (free_dof[i]) rhs.push_back(b[i] - Ac[i]);
        if (L.n > 0) chol_.solve(rhs.data(), sol.data());
        for (std::size_t i = 0, j = 0; i < n; ++i)
            if (free_dof[i]) x[i] = sol[j++];
        // Indefinite A: LDL^T still solves, but report it like CG would.
        res.negative_curvature = chol_.used_ldlt() && chol_.indefinite();
        // |A sol - rhs| / |rhs| with the lower triangle (symmetric A).
        std::vector<double> r(rhs.size());
        for (std::size_t j = 0; j < r.size(); ++j) r[j] = -rhs[j];
        for (index_t j = 0; j < L.n; ++j)
            for (index_t e = L.col_start[std::size_t(j)]; e < L.col_start[std::size_t(j) + 1]; ++e) {
                const auto i = std::size_t(L.row[std::size_t(e)]);
                r[i] += L.value[std::size_t(e)] * sol[std::size_t(j)];
                if (i != std::size_t(j)) r[std::size_t(j)] += L.value[std::size_t(e)] * sol[i];
            }
        double rr = 0, bb = 0;
        for (std::size_t j = 0; j < r.size(); ++j) {
            rr += r[j] * r[j];
            bb += rhs[j] * rhs[j];
        }
        res.residual = std::sqrt(rr) / std::max(std::sqrt(bb), 1e-300);
        res.converged = std::isfinite(res.residual) && !res.negative_curvature;
        return res;
    }

private:
    const SimState<S>& s_;
    SystemMatrix<S> matrix_;
    SparseCholesky chol_;
    bool factored_ = false;
};

}  // namespace

template <class S>
std::unique_ptr<SystemSolver<S>> make_direct_solver(const SimState<S>& state) {
    return std::make_unique<DirectSolver<S>>(state);
}

template std::unique_ptr<SystemSolver<double>> make_direct_solver(const SimState<double>&);
template std::unique_ptr<SystemSolver<float>> make_direct_solver(const SimState<float>&);

}  // namespace edgefem::sim
