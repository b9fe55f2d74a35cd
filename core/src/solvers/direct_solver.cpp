// The assembled path: A on the free dofs as an Eigen sparse matrix
// (sparse_assembly.hpp), factorised by SimplicialLDLT. On the host: b and x
// through host() (back-ends with host memory).
#include <Eigen/SparseCholesky>
#include <cmath>
#include <utility>

#include "edgefem/core/sparse_assembly.hpp"
#include "solvers/system_solver.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class DirectSolver final : public SystemSolver<S> {
public:
    explicit DirectSolver(const SimState<S>& state) : s_(state) {}

    bool reusable() const override { return false; }

    void setup(LinearSystem<S>& A) override {
        nf_ = number_free_dofs(s_.free_host, dof_index_);
        std::vector<std::pair<double, const ElasticOperator<S>*>> terms{{A.c_k(), &A.K()}};
        if (A.c_b() != 0) terms.emplace_back(A.c_b(), A.K0());
        matrix_ = assemble_system(dof_index_, nf_, A.c_m(), s_.mass_host, terms);
        ldlt_.compute(matrix_);
    }

    CgResult solve(LinearSystem<S>& A, BackendVector<double>& b_vec, BackendVector<double>& x_vec, double,
                   int) override {
        CgResult res;
        const std::size_t n = s_.n();
        const std::span<const double> b = b_vec.host();
        const std::span<double> x = x_vec.host();
        const auto& free_dof = s_.free_host;
        // rhs = b - A x_constrained
        BackendVector<double> xc_vec = s_.template vector<double>(n), Ac_vec = s_.template vector<double>(n);
        const std::span<double> xc = xc_vec.host(), Ac = Ac_vec.host();
        for (std::size_t i = 0; i < n; ++i) xc[i] = free_dof[i] ? 0.0 : x[i];
        A.apply(xc.data(), Ac.data());
        Eigen::VectorXd rhs(nf_);
        for (std::size_t i = 0; i < n; ++i)
            if (dof_index_[i] >= 0) rhs[dof_index_[i]] = b[i] - Ac[i];
        if (ldlt_.info() != Eigen::Success) {
            res.residual = INFINITY;
            return res;
        }
        const Eigen::VectorXd sol = ldlt_.solve(rhs);
        for (std::size_t i = 0; i < n; ++i)
            if (dof_index_[i] >= 0) x[i] = sol[dof_index_[i]];
        // Indefinite A: LDLT still solves, but report it like CG would.
        const auto D = ldlt_.vectorD();
        res.negative_curvature = (D.array() <= 0).any();
        // Norms summed by hand: Eigen's reductions trip g++ 12.2's false
        // -Wmaybe-uninitialized inside its AVX-512 code (GCC PR 105593).
        const Eigen::VectorXd r = matrix_ * sol - rhs;
        double rr = 0, bb = 0;
        for (Eigen::Index i = 0; i < r.size(); ++i) {
            rr += r[i] * r[i];
            bb += rhs[i] * rhs[i];
        }
        res.residual = std::sqrt(rr) / std::max(std::sqrt(bb), 1e-300);
        res.converged = std::isfinite(res.residual) && !res.negative_curvature;
        return res;
    }

private:
    const SimState<S>& s_;
    std::vector<index_t> dof_index_;
    index_t nf_ = 0;
    Eigen::SparseMatrix<double> matrix_;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
};

}  // namespace

template <class S>
std::unique_ptr<SystemSolver<S>> make_direct_solver(const SimState<S>& state) {
    return std::make_unique<DirectSolver<S>>(state);
}

template std::unique_ptr<SystemSolver<double>> make_direct_solver(const SimState<double>&);
template std::unique_ptr<SystemSolver<float>> make_direct_solver(const SimState<float>&);

}  // namespace edgefem::sim
