// Matrix-free CG (the back-end's cg kernel) on the per-edge K with the
// scene's preconditioner; right-hand sides of extreme magnitude are
// scaled by a power of two first.
#include <algorithm>
#include <cmath>

#include "solvers/preconditioner.hpp"
#include "solvers/system_solver.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class CgSolver final : public SystemSolver<S> {
public:
    explicit CgSolver(const SimState<S>& state)
        : s_(state), precond_(make_preconditioner(state)), work_(state.backend->memory()),
          Ad_(state.template vector<double>(0)) {}

    bool reusable() const override { return true; }
    int refreshes() const override { return precond_->refreshes(); }
    void setup(LinearSystem<S>& A) override { precond_->setup(A); }
    void save(CheckpointWriter& w) const override { precond_->save(w); }
    void load(CheckpointReader& r, LinearSystem<S>& A) override { precond_->load(r, A); }

    CgResult solve(LinearSystem<S>& A, BackendVector<double>& b, BackendVector<double>& x, double tolerance,
                   int fixed_iterations, const double* direction) override {
        const double s = solve_scale(A.c_m(), b, x);
        if (s != 1) s_.kernels.rescale(b.data(), x.data(), s_.n(), s, true);
        if (direction && fixed_iterations == 0) improve_start(A, b, x, direction);
        const int max_it = s_.scene.solver.cg_max_iterations;
        const int after = fixed_iterations == 0 ? precond_->switch_after() : 0;
        const bool may_switch = after > 0 && after < max_it;
        CgResult res = run(A, b, x, tolerance, may_switch ? after : max_it, fixed_iterations);
        if (may_switch && !res.converged && !res.negative_curvature) {
            // Warm-started from the iterate reached: the residual is relative to
            // the same right side, so the tolerance means what it meant.
            precond_->switch_now(A, res.residual);
            const int before = res.iterations;
            res = run(A, b, x, tolerance, max_it - before, 0);
            res.iterations += before;
        }
        if (s != 1) s_.kernels.rescale(b.data(), x.data(), s_.n(), s, false);
        // A solve cut short by negative curvature (the step falls back to
        // the definite K) says nothing about the preconditioner's rate.
        if (!res.negative_curvature) precond_->solved(res.iterations, res.residual);
        if (precond_->indefinite()) {  // see Preconditioner::indefinite
            res.negative_curvature = true;
            res.converged = false;
        }
        return res;
    }

private:
    // x += alpha d with the alpha that minimises the A-norm of the error
    // along d: alpha = d.(b - A x) / d.A d, d zero on constrained dofs (none
    // where d.A d is not positive). One product: A is symmetric, so
    // d.A x = x.A d over all dofs (A's constrained rows included, which
    // couple the constrained values of x to the free dofs of d). The
    // semi-implicit step's d, the change of velocity over the last step,
    // takes 7-34 % of block-Jacobi's CG iterations off its solves at 1 ms
    // (docs/solvers.md, "Warm start").
    void improve_start(LinearSystem<S>& A, const BackendVector<double>& b, BackendVector<double>& x,
                       const double* d) {
        const VectorKernels<S>& k = s_.kernels;
        const std::size_t n = s_.n();
        Ad_.resize(n);
        A.apply(d, Ad_.data());
        const std::array<double, 3> s = k.warm_start_sums(d, b.data(), x.data(), Ad_.data(), n);
        const double alpha = (s[0] - s[1]) / s[2];
        if (s[2] > 0 && std::isfinite(alpha)) k.axpby(x.data(), alpha, d, 1.0, n);
    }

    CgResult run(LinearSystem<S>& A, BackendVector<double>& b, BackendVector<double>& x, double tolerance, int max_it,
                 int fixed_iterations) {
        return s_.kernels.cg(A, *precond_, s_.free_dof.data(), b.data(), x.data(), s_.n(),
                             {tolerance, max_it, fixed_iterations}, work_);
    }

    // A power of two s with b / s and the mass part of A x / s near 1 when
    // they are extreme, else 1. CG's dot products square its vectors: for a
    // body whose motion has decayed to 1e-150 m they underflow into
    // subnormals and CG breaks down (false negative curvature, a Newton
    // direction of noise). Scaling by a power of two is exact, so a solve
    // that needs no scaling is unchanged.
    double solve_scale(double c_m, const BackendVector<double>& b, const BackendVector<double>& x) const {
        const std::array<double, 3> m =
            s_.kernels.solve_magnitudes(b.data(), x.data(), s_.mass_dof.data(), s_.free_dof.data(), s_.n());
        const double mag = std::max(m[0], c_m * m[2] * m[1]);
        if (!(mag > 0) || !std::isfinite(mag) || (mag > 0x1p-100 && mag < 0x1p100)) return 1;
        return std::ldexp(1.0, std::ilogb(mag));
    }

    const SimState<S>& s_;
    std::unique_ptr<Preconditioner<S>> precond_;
    CgWork work_;
    BackendVector<double> Ad_;  // improve_start's
};

}  // namespace

template <class S>
std::unique_ptr<SystemSolver<S>> make_cg_solver(const SimState<S>& state) {
    return std::make_unique<CgSolver<S>>(state);
}

template std::unique_ptr<SystemSolver<double>> make_cg_solver(const SimState<double>&);
template std::unique_ptr<SystemSolver<float>> make_cg_solver(const SimState<float>&);

}  // namespace edgefem::sim
