// Matrix-free CG (cg.hpp) on the per-edge K with a block-Jacobi
// preconditioner; right-hand sides of extreme magnitude are scaled by a
// power of two first.
#include <algorithm>
#include <array>
#include <cmath>

#include "solvers/preconditioner.hpp"
#include "solvers/system_solver.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class CgSolver final : public SystemSolver<S> {
public:
    explicit CgSolver(const SimState<S>& state) : s_(state), precond_(make_block_jacobi(state)) {}

    bool reusable() const override { return true; }
    void setup(LinearSystem<S>& A) override { precond_->setup(A); }

    CgResult solve(LinearSystem<S>& A, std::vector<double>& b, std::vector<double>& x, double tolerance,
                   int fixed_iterations) override {
        const double s = solve_scale(A.c_m(), b, x);
        if (s != 1) s_.each([&](std::size_t i) {
            b[i] /= s;
            x[i] /= s;
        });
        const Preconditioner<S>& M = *precond_;
        const CgResult res = conjugate_gradient(
            *s_.exec, s_.n(), s_.free_dof.data(), [&](const double* in, double* out) { A.products(in, out); },
            [&](std::size_t lo, std::size_t hi, const double* in, double* out) { A.finish(lo, hi, in, out); },
            [&](std::size_t lo, std::size_t hi, const double* r, double* z) { M.apply(lo, hi, r, z); }, b.data(),
            x.data(), tolerance, s_.scene.solver.cg_max_iterations, fixed_iterations, work_);
        if (s != 1) s_.each([&](std::size_t i) {
            b[i] *= s;
            x[i] *= s;
        });
        return res;
    }

private:
    // A power of two s with b / s and the mass part of A x / s near 1 when
    // they are extreme, else 1. CG's dot products square its vectors: for a
    // body whose motion has decayed to 1e-150 m they underflow into
    // subnormals and CG breaks down (false negative curvature, a Newton
    // direction of noise). Scaling by a power of two is exact, so a solve
    // that needs no scaling is unchanged.
    double solve_scale(double c_m, const std::vector<double>& b, const std::vector<double>& x) const {
        // Maxima per block on the executor (exact in any order).
        const auto& free_dof = s_.free_dof;
        const auto& mass_dof = s_.mass_dof;
        std::vector<std::array<double, 3>> part(vector_blocks(s_.n()), {0.0, 0.0, 0.0});
        for_blocks(*s_.exec, s_.n(), [&](std::size_t lo, std::size_t hi) {
            double bm = 0, xm = 0, mm = 0;
            for (std::size_t i = lo; i < hi; ++i) {
                if (free_dof[i]) bm = std::max(bm, std::abs(b[i]));
                xm = std::max(xm, std::abs(x[i]));
                mm = std::max(mm, mass_dof[i]);
            }
            part[lo / kVectorBlock] = {bm, xm, mm};
        });
        double bmax = 0, xmax = 0, mmax = 0;
        for (const auto& p : part) {
            bmax = std::max(bmax, p[0]);
            xmax = std::max(xmax, p[1]);
            mmax = std::max(mmax, p[2]);
        }
        const double mag = std::max(bmax, c_m * mmax * xmax);
        if (!(mag > 0) || !std::isfinite(mag) || (mag > 0x1p-100 && mag < 0x1p100)) return 1;
        return std::ldexp(1.0, std::ilogb(mag));
    }

    const SimState<S>& s_;
    std::unique_ptr<Preconditioner<S>> precond_;
    CgWork work_;
};

}  // namespace

template <class S>
std::unique_ptr<SystemSolver<S>> make_cg_solver(const SimState<S>& state) {
    return std::make_unique<CgSolver<S>>(state);
}

template std::unique_ptr<SystemSolver<double>> make_cg_solver(const SimState<double>&);
template std::unique_ptr<SystemSolver<float>> make_cg_solver(const SimState<float>&);

}  // namespace edgefem::sim
