#include "edgefem/core/simulator.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "edgefem/core/cg.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/sparse_assembly.hpp"

namespace edgefem {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// %.3e, for residuals in messages (std::to_string prints 0.000000).
std::string sci(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", v);
    return buf;
}

// A load fraction with the digits that tell close increments apart.
std::string fmt_load(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

// Inverse of the symmetric part of B (row-major into inv) by Cholesky;
// false when it is not positive definite. Written out for 3x3: Eigen's LLT
// solve against the identity went through its general triangular solver
// and made the block-Jacobi set-up ~5% of a semi-implicit step.
bool spd_inverse3(const double (&B)[3][3], double* inv) {
    const double a00 = B[0][0], a11 = B[1][1], a22 = B[2][2];
    const double a10 = 0.5 * (B[1][0] + B[0][1]), a20 = 0.5 * (B[2][0] + B[0][2]), a21 = 0.5 * (B[2][1] + B[1][2]);
    if (!(a00 > 0)) return false;
    const double l00 = std::sqrt(a00), l10 = a10 / l00, l20 = a20 / l00;
    const double d11 = a11 - l10 * l10;
    if (!(d11 > 0)) return false;
    const double l11 = std::sqrt(d11), l21 = (a21 - l20 * l10) / l11;
    const double d22 = a22 - l20 * l20 - l21 * l21;
    if (!(d22 > 0)) return false;
    const double l22 = std::sqrt(d22);
    // M = L^-1 (lower triangular), inv = M^T M.
    const double m00 = 1 / l00, m11 = 1 / l11, m22 = 1 / l22;
    const double m10 = -l10 * m00 * m11, m21 = -l21 * m11 * m22, m20 = -(l20 * m00 + l21 * m10) * m22;
    inv[0] = m00 * m00 + m10 * m10 + m20 * m20;
    inv[1] = inv[3] = m10 * m11 + m20 * m21;
    inv[2] = inv[6] = m20 * m22;
    inv[4] = m11 * m11 + m21 * m21;
    inv[5] = inv[7] = m21 * m22;
    inv[8] = m22 * m22;
    return true;
}

// K sums at once: block(lo, hi) gives a block's K partials, which are added
// in block order, as blocked_sum: the same for any thread count.
template <std::size_t K, class Block>
std::array<double, K> blocked_sums(const Executor& ex, std::size_t n, Block&& block) {
    std::vector<std::array<double, K>> partial(vector_blocks(n));
    for_blocks(ex, n, [&](std::size_t lo, std::size_t hi) { partial[lo / kVectorBlock] = block(lo, hi); });
    std::array<double, K> s{};
    for (const auto& p : partial)
        for (std::size_t k = 0; k < K; ++k) s[k] += p[k];
    return s;
}

// Sums of squares and products for Newton without underflow: a damped
// body's motion decays to 1e-160 m and below, whose squares leave the double
// range (a zero slope, a zero norm, a Newton iteration of noise). Each
// vector is scaled by a power of two near its largest entry first (exact);
// the result is mant x 2^exp. A non-finite entry makes it non-finite.
struct Scaled {
    double mant = 0;
    int exp = 0;
    double value() const { return std::ldexp(mant, exp); }
};

// The exponent of the largest |term(i)|; `bad` gets the last non-finite
// one in index order. Per block on the executor (a maximum is exact in any
// order), so that Newton has no serial pass over the dofs.
template <class Term>
int max_exponent(const Executor& ex, std::size_t n, Term&& term, double& bad) {
    std::vector<std::array<double, 2>> part(vector_blocks(n), {0.0, 0.0});  // {max, last non-finite}
    for_blocks(ex, n, [&](std::size_t lo, std::size_t hi) {
        double mx = 0, b = 0;
        for (std::size_t i = lo; i < hi; ++i) {
            const double t = std::abs(term(i));
            if (!std::isfinite(t)) b = t;
            mx = std::max(mx, t);
        }
        part[lo / kVectorBlock] = {mx, b};
    });
    double mx = 0;
    for (const auto& p : part) {
        if (p[1] != 0) bad = p[1];
        mx = std::max(mx, p[0]);
    }
    return mx > 0 ? std::ilogb(mx) : 0;
}

template <class A, class B>
Scaled scaled_dot(const Executor& ex, std::size_t n, A&& a, B&& b) {
    double bad = 0;
    const int ea = max_exponent(ex, n, a, bad), eb = max_exponent(ex, n, b, bad);
    if (bad != 0) return {bad, 0};
    return {blocked_sum(ex, n, [&](std::size_t i) { return std::ldexp(a(i), -ea) * std::ldexp(b(i), -eb); }), ea + eb};
}

template <class Term>
double scaled_norm(const Executor& ex, std::size_t n, Term&& term) {
    const Scaled s = scaled_dot(ex, n, term, term);
    return std::isfinite(s.mant) ? std::ldexp(std::sqrt(s.mant), s.exp / 2) : s.mant;
}

// The energy guard's view of a state (SolverSettings::max_energy_growth).
struct EnergySample {
    double kinetic = 0, elastic = 0;
    double gravity = 0;  // -m g.u (the constant -m g.X left out: only differences count)
    double load = 0;     // f_ext.u with the step's f_ext: its change is the external work
    double total() const { return kinetic + elastic + gravity; }
    double magnitude() const { return kinetic + std::abs(elastic) + std::abs(gravity) + std::abs(load); }
};

// A failed step, caught to retry with a halved step.
struct StepFailure {
    std::string message;
    index_t vertex;
};

}  // namespace

template <class S>
struct Simulator<S>::Impl {
    Scene scene;
    std::shared_ptr<const Executor> exec;
    OperatorFactory<S> factory;
    std::unique_ptr<ElasticOperator<S>> op;
    std::unique_ptr<ElasticOperator<S>> op_damp;  // K frozen at the step start (implicit, beta > 0)
    std::vector<double> mass;                     // #V
    std::vector<double> mass_dof;                 // 3 #V: mass per dof, for loops that vectorise
    std::vector<S> u, v, fext, f;                 // 3 #V
    std::vector<S> step_start_u, step_start_v;    // the state before the step (restored when it fails)
    double ramp_floor = 0;                        // 1 after solve_static: the prescribed targets are reached
    std::vector<std::uint8_t> free_dof;           // 3 #V
    std::vector<index_t> con_vertex;              // fixed and prescribed vertices
    std::vector<std::array<double, 3>> con_disp;  // their final displacement
    StepStats stats;
    int stiffness_age = 0;     // semi-implicit steps since K was built (0: none yet)
    double stiffness_dt = 0;   // the step size K's system matrix was built for
    long step = 0;
    double time = 0;

    // Scratch.
    std::vector<double> h, x, b, Ax, Dinv;
    std::vector<S> xs, ys, D, D0;   // D, D0: diagonal blocks of K and K0 (9 #V)
    std::vector<double> newton_d;   // u - u0 in Newton's residual
    CgWork cg;
    std::vector<index_t> dof_index;

    // Energy guard (SolverSettings::max_energy_growth).
    std::vector<S> u_evaluated;    // the u that f, the operator's state and W_evaluated belong to
    double W_evaluated = 0;
    bool evaluated_valid = false;
    bool forces_current = false;   // f is at the step's starting u: the step skips its force pass
    double energy_excess = 0;      // energy gained net of work since its lowest level (>= 0)
    double energy_scale = 0;       // largest kinetic + elastic energy seen
    double newton_W = 0;           // elastic energy at Newton's last evaluation

    std::size_t n() const { return u.size(); }

    // body(i) for every dof / vertex, in fixed blocks on the executor: the
    // per-step O(n) work never runs as a serial section.
    template <class Body>
    void each(Body&& body) const {
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) body(i);
        });
    }
    // dst = src over the dofs' blocks on the executor, as `each` splits
    // them: each thread copies the part of the state it updates. Copied on
    // the calling thread, the whole of u and v passed through its cache once
    // a step, and the other thread's next writes there waited for those
    // lines to be taken back (bunny-4k at 2 threads: the step's u and v
    // update took 9.1 us, 7.7 with the copies here, 1.2 at 1 thread), and
    // the copies were a serial O(n) part of every step.
    template <class T>
    void copy_state(std::vector<T>& dst, const std::vector<T>& src) const {
        dst.resize(src.size());
        for_blocks(*exec, src.size(), [&](std::size_t lo, std::size_t hi) {
            std::copy(src.begin() + std::ptrdiff_t(lo), src.begin() + std::ptrdiff_t(hi), dst.begin() + std::ptrdiff_t(lo));
        });
    }
    // Over the dofs' blocks, each a whole number of vertices (kVectorBlock
    // is a multiple of 3): blocks of kVectorBlock vertices left bunny-4k's
    // 1141 vertices 3 blocks, too few to share, and its preconditioner
    // (a 3x3 inverse per vertex) on one thread.
    template <class Body>
    void each_vertex(Body&& body) const {
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
            for (std::size_t v = lo / 3; v < hi / 3; ++v) body(v);
        });
    }

    Impl(Scene s, std::shared_ptr<const Executor> e, OperatorFactory<S> make_op)
        : scene(std::move(s)), exec(std::move(e)), factory(std::move(make_op)) {
        scene.validate();
        if (!exec) exec = std::make_shared<SerialExecutor>();
        if (!factory) factory = [](const Mesh& m, const Materials& mat, ModelKind k, Method me) {
            return make_reference_operator<S>(m, mat, k, me);
        };
        const Mesh& mesh = scene.mesh;
        op = factory(mesh, scene.materials, scene.model, scene.method);
        if (scene.integrator == Integrator::Explicit) op->keep_state(false);  // explicit steps never build K
        mass = edgefem::lumped_mass(mesh, scene.materials);
        mass_dof.resize(3 * mass.size());
        for (std::size_t i = 0; i < mass_dof.size(); ++i) mass_dof[i] = mass[i / 3];
        const std::size_t nd = 3 * std::size_t(mesh.num_vertices());
        u.assign(nd, S(0));
        v.assign(nd, S(0));
        fext.assign(nd, S(0));
        f.assign(nd, S(0));
        free_dof.assign(nd, 1);
        for (index_t vtx : scene.fixed) {
            con_vertex.push_back(vtx);
            con_disp.push_back({0, 0, 0});
        }
        for (const auto& p : scene.prescribed) {
            con_vertex.push_back(p.vertex);
            con_disp.push_back({p.target[0] - mesh.X[3 * std::size_t(p.vertex)],
                                p.target[1] - mesh.X[3 * std::size_t(p.vertex) + 1],
                                p.target[2] - mesh.X[3 * std::size_t(p.vertex) + 2]});
        }
        for (index_t vtx : con_vertex)
            for (int r = 0; r < 3; ++r) free_dof[3 * std::size_t(vtx) + r] = 0;
        for (std::size_t i = 0; i < mass.size(); ++i)
            if (!(mass[i] > 0))
                throw InvalidArgument("scene: vertex " + std::to_string(i) + " has no mass (unreferenced vertex?)");
        h.resize(nd);
        x.resize(nd);
        b.resize(nd);
        Ax.resize(nd);
        Dinv.resize(9 * std::size_t(mesh.num_vertices()) + 1);  // + 1: the last 4-lane row read (preconditioner)
    }

    // External load h = load (M g + f_ext).
    void external(double load) {
        each([&](std::size_t i) { h[i] = load * (mass[i / 3] * scene.gravity[i % 3] + double(fext[i])); });
    }

    // Fraction of the prescribed targets reached at time t.
    double ramp(double t) const {
        return std::max(ramp_floor, std::min(1.0, t / (scene.prescribed_steps * scene.dt) * (1 + 1e-12)));
    }

    // y = op x with double vectors (converts for float models).
    void multiply(const ElasticOperator<S>& K, const double* in, double* out) {
        if constexpr (std::is_same_v<S, double>) {
            K.multiply(in, out);
        } else {
            xs.resize(n());
            ys.resize(n());
            each([&](std::size_t i) { xs[i] = S(in[i]); });
            K.multiply(xs.data(), ys.data());
            each([&](std::size_t i) { out[i] = double(ys[i]); });
        }
    }

    // A = c_m M + c_k K + c_b K0, in two parts (as conjugate_gradient takes
    // it): the products K x (and K0 x into Ax), then per block the diagonal
    // mass term and the sum.
    void apply_products(double c_b, const double* in, double* out) {
        multiply(*op, in, out);
        if (c_b != 0) multiply(*op_damp, in, Ax.data());
    }
    // Mass per dof, scalars by value: vectorises (over mass[i / 3] with
    // c_m, c_k by reference it did not).
    void finish_system(double c_m, double c_k, double c_b, std::size_t lo, std::size_t hi, const double* in,
                       double* out) const {
        const double* __restrict m = mass_dof.data();
        const double* __restrict xin = in;
        double* __restrict y = out;
        for (std::size_t i = lo; i < hi; ++i) y[i] = c_m * m[i] * xin[i] + c_k * y[i];
        if (c_b != 0) {
            const double* __restrict a = Ax.data();
            for (std::size_t i = lo; i < hi; ++i) y[i] += c_b * a[i];
        }
    }
    void apply_system(double c_m, double c_k, double c_b, const double* in, double* out) {
        apply_products(c_b, in, out);
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) { finish_system(c_m, c_k, c_b, lo, hi, in, out); });
    }

    // Block-Jacobi: inverse of each vertex's 3x3 diagonal block of A; a
    // block that is not positive definite falls back to its mass part so
    // the preconditioner stays SPD.
    void build_preconditioner(double c_m, double c_k, double c_b) {
        D.resize(9 * mass.size());
        op->diagonal_blocks(D.data());
        if (c_b != 0) {
            D0.resize(D.size());
            op_damp->diagonal_blocks(D0.data());
        }
        each_vertex([&](std::size_t vtx) {
            double B[3][3];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    B[i][j] = c_k * double(D[9 * vtx + 3 * i + j]) + (c_b != 0 ? c_b * double(D0[9 * vtx + 3 * i + j]) : 0.0) +
                              (i == j ? c_m * mass[vtx] : 0.0);
            double* inv = &Dinv[9 * vtx];
            if (!spd_inverse3(B, inv)) {
                const double d = std::max({c_m * mass[vtx], B[0][0], B[1][1], B[2][2], 1e-300});
                for (int i = 0; i < 9; ++i) inv[i] = (i % 4 == 0) ? 1 / d : 0.0;
            }
        });
    }

    // Solves A x = b on the free dofs; x holds the constrained values and a
    // warm start. Builds K (definite if asked) first; on negative curvature
    // with the plain K it retries once with the definite K.
    // `reuse_stiffness`: keep the K and preconditioner of an earlier solve
    // (matrix-free CG only; see SolverSettings::stiffness_interval).
    // `fixed_iterations` > 0: exactly that many CG iterations (the
    // semi-implicit step's budget, cg_fixed_iterations; Newton's solves
    // always run to their tolerance: with the budget they failed to converge).
    CgResult solve(double c_m, double c_k, double c_b, double tolerance, bool definite, bool reuse_stiffness = false,
                   int fixed_iterations = 0) {
        CgResult res = solve_once(c_m, c_k, c_b, tolerance, definite, reuse_stiffness, fixed_iterations);
        if (res.negative_curvature && !definite && scene.method == Method::Edge) {
            stats.negative_curvature = true;
            const int its = res.iterations;
            res = solve_once(c_m, c_k, c_b, tolerance, true, false, fixed_iterations);
            res.iterations += its;
        }
        return res;
    }

    // A power of two s with b / s and the mass part of A x / s near 1 when
    // they are extreme, else 1. CG's dot products square its vectors: for a
    // body whose motion has decayed to 1e-150 m they underflow into
    // subnormals and CG breaks down (false negative curvature, a Newton
    // direction of noise). Scaling by a power of two is exact, so a solve
    // that needs no scaling is unchanged.
    double solve_scale(double c_m) const {
        // Maxima per block on the executor (exact in any order).
        std::vector<std::array<double, 3>> part(vector_blocks(n()), {0.0, 0.0, 0.0});
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
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

    CgResult solve_once(double c_m, double c_k, double c_b, double tolerance, bool definite,
                        bool reuse_stiffness = false, int fixed_iterations = 0) {
        auto t0 = Clock::now();
        reuse_stiffness = reuse_stiffness && scene.solver.linear_solver == LinearSolver::CG;
        if (!reuse_stiffness) op->build_stiffness(definite);
        CgResult res;
        if (scene.solver.linear_solver == LinearSolver::Direct) {
            const index_t nf = number_free_dofs(free_dof, dof_index);
            std::vector<std::pair<double, const ElasticOperator<S>*>> terms{{c_k, op.get()}};
            if (c_b != 0) terms.emplace_back(c_b, op_damp.get());
            const Eigen::SparseMatrix<double> A = assemble_system(dof_index, nf, c_m, mass, terms);
            Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
            stats.stiffness_ms += ms_since(t0);
            t0 = Clock::now();
            // rhs = b - A x_constrained
            std::vector<double> xc(n());
            for (std::size_t i = 0; i < n(); ++i) xc[i] = free_dof[i] ? 0.0 : x[i];
            std::vector<double> Ac(n());
            apply_system(c_m, c_k, c_b, xc.data(), Ac.data());
            Eigen::VectorXd rhs(nf);
            for (std::size_t i = 0; i < n(); ++i)
                if (dof_index[i] >= 0) rhs[dof_index[i]] = b[i] - Ac[i];
            if (ldlt.info() != Eigen::Success) {
                res.residual = INFINITY;
                stats.solve_ms += ms_since(t0);
                return res;
            }
            const Eigen::VectorXd sol = ldlt.solve(rhs);
            for (std::size_t i = 0; i < n(); ++i)
                if (dof_index[i] >= 0) x[i] = sol[dof_index[i]];
            // Indefinite A: LDLT still solves, but report it like CG would.
            const auto D = ldlt.vectorD();
            res.negative_curvature = (D.array() <= 0).any();
            // Norms summed by hand: Eigen's reductions trip g++ 12.2's false
            // -Wmaybe-uninitialized inside its AVX-512 code (GCC PR 105593).
            const Eigen::VectorXd r = A * sol - rhs;
            double rr = 0, bb = 0;
            for (Eigen::Index i = 0; i < r.size(); ++i) {
                rr += r[i] * r[i];
                bb += rhs[i] * rhs[i];
            }
            res.residual = std::sqrt(rr) / std::max(std::sqrt(bb), 1e-300);
            res.converged = std::isfinite(res.residual) && !res.negative_curvature;
            stats.solve_ms += ms_since(t0);
            return res;
        }
        if (!reuse_stiffness) build_preconditioner(c_m, c_k, c_b);
        stats.stiffness_ms += ms_since(t0);
        t0 = Clock::now();
        const double s = solve_scale(c_m);
        if (s != 1) each([&](std::size_t i) {
            b[i] /= s;
            x[i] /= s;
        });
        res = conjugate_gradient(
            *exec, n(), free_dof.data(), [&](const double* in, double* out) { apply_products(c_b, in, out); },
            [&](std::size_t lo, std::size_t hi, const double* in, double* out) {
                finish_system(c_m, c_k, c_b, lo, hi, in, out);
            },
            [&](std::size_t lo, std::size_t hi, const double* r_in, double* z_out) {
                const double* __restrict r = r_in;
                double* __restrict z = z_out;
                const double* __restrict Minv = Dinv.data();
                // z = Dinv r per vertex as rows times broadcasts in 4-lane
                // vectors: Dinv is exactly symmetric (spd_inverse3), so its
                // rows are its columns; lane 3 reads the next value (Dinv
                // has one spare at the end) and is never stored.
                typedef double V4 __attribute__((vector_size(32)));
                for (std::size_t vtx = lo / 3; vtx < hi / 3; ++vtx) {
                    const double* M = &Minv[9 * vtx];
                    const double* rv = &r[3 * vtx];
                    V4 m0, m1, m2;
                    __builtin_memcpy(&m0, M, sizeof m0);
                    __builtin_memcpy(&m1, M + 3, sizeof m1);
                    __builtin_memcpy(&m2, M + 6, sizeof m2);
                    const V4 zv = rv[0] * m0 + rv[1] * m1 + rv[2] * m2;
                    for (int i = 0; i < 3; ++i) z[3 * vtx + i] = zv[i];
                }
            },
            b.data(), x.data(), tolerance, scene.solver.cg_max_iterations, fixed_iterations, cg);
        if (s != 1) each([&](std::size_t i) {
            b[i] *= s;
            x[i] *= s;
        });
        stats.solve_ms += ms_since(t0);
        stats.solver_iterations += res.iterations;
        return res;
    }

    double forces(bool energy) {
        const auto t0 = Clock::now();
        const double W = op->forces(u.data(), f.data(), energy);
        stats.force_ms += ms_since(t0);
        return W;
    }

    // The internal forces at the step's start, unless the energy guard has
    // just evaluated them at this state.
    void start_forces() {
        if (!forces_current) forces(false);
        forces_current = false;
    }

    // Kinetic energy, gravity's potential and f_ext.u, per block as
    // block_sum's interleaved sums over its vertices (a block holds whole
    // vertices: kVectorBlock is a multiple of 3). One running sum per term,
    // through the dofs, took 6.5 us per call on bunny-4k (3423 dofs).
    EnergySample sample(double W) const {
        const double g0 = scene.gravity[0], g1 = scene.gravity[1], g2 = scene.gravity[2];
        const std::array<double, 3> s = blocked_sums<3>(*exec, n(), [&](std::size_t lo, std::size_t hi) {
            const std::size_t a0 = lo / 3, a1 = hi / 3;
            const auto d = [](S x) { return double(x); };
            const double kinetic = block_sum(a0, a1, [&](std::size_t a) {
                const double vx = d(v[3 * a]), vy = d(v[3 * a + 1]), vz = d(v[3 * a + 2]);
                return mass[a] * (vx * vx + vy * vy + vz * vz);
            });
            const double gravity = block_sum(a0, a1, [&](std::size_t a) {
                return mass[a] * (g0 * d(u[3 * a]) + g1 * d(u[3 * a + 1]) + g2 * d(u[3 * a + 2]));
            });
            const double load = block_sum(lo, hi, [&](std::size_t i) { return d(fext[i]) * d(u[i]); });
            return std::array<double, 3>{0.5 * kinetic, -gravity, load};
        });
        return {s[0], W, s[1], s[2]};
    }

    // The state at the start of a step. The elastic energy comes from the
    // guard's force pass at the end of the last step when u is unchanged
    // since (then f is current too and the step skips its force pass), else
    // from a force pass here. Edits the application made between steps are
    // thereby part of the starting energy, not of the step's gain.
    EnergySample energy_at_start() {
        // Compared block by block on the executor, as copy_state copies.
        const bool same = evaluated_valid && blocked_sum(*exec, n(), [&](std::size_t i) {
                                                 return u[i] == u_evaluated[i] ? 0.0 : 1.0;
                                             }) == 0;
        const double W = same ? W_evaluated : forces(true);
        forces_current = true;
        return sample(W);
    }

    // Whether a step from the current state to t_end moves a fixed or
    // prescribed vertex (a prescribed ramp, or a vertex the application
    // displaced): the constraint's work is unknown, so the guard skips it.
    bool constraints_move(double t_end) const {
        const double s = ramp(t_end), tol = 8 * double(std::numeric_limits<S>::epsilon());
        for (std::size_t k = 0; k < con_vertex.size(); ++k)
            for (int r = 0; r < 3; ++r) {
                const double target = s * con_disp[k][r], cur = double(u[3 * std::size_t(con_vertex[k]) + r]);
                if (std::abs(target - cur) > tol * (std::abs(target) + std::abs(cur))) return true;
            }
        return false;
    }

    // The energy guard after a step of size T that started at `start` and
    // ends with elastic energy W_end. The step's gain is its energy change
    // net of the external work (f_ext is constant over the step: f_ext.du)
    // and of what mass damping removed (every integrator applies alpha M v
    // with the new velocity over du = T v: 2 T alpha x kinetic energy), so it
    // is the integrator's own energy error: damping does not hide an
    // injection. Gains accumulate from their lowest level (a one-sided
    // CUSUM: dissipation is no credit for later injection) and may not
    // exceed (max_energy_growth - 1) x the largest kinetic + elastic energy
    // the body has had net of such gains, plus the sums' round-off.
    void check_energy(double T, const EnergySample& start, double W_end, bool constraints_moved) {
        copy_state(u_evaluated, u);
        W_evaluated = W_end;
        evaluated_valid = true;
        const EnergySample end = sample(W_end);
        // The reference is net of the gains counted so far: the start's own
        // kinetic + elastic energy includes them, and with it a steady
        // growth of 1.2-3x per step raised its own bound and was never
        // caught (a bent beam, explicit just past the stable dt, reached
        // 460x its release energy with every step passing).
        const double scale = std::max(energy_scale, start.kinetic + start.elastic - energy_excess);
        double excess = energy_excess;
        if (!constraints_moved) {
            const double damping = 2 * T * scene.rayleigh_alpha * end.kinetic;
            const double gain = (end.total() - start.total()) - (end.load - start.load) + damping;
            const double noise = 256 * double(std::numeric_limits<S>::epsilon()) * (start.magnitude() + end.magnitude());
            excess += gain;
            const double limit = scene.solver.max_energy_growth;
            stats.energy_growth = 1 + std::max(excess, 0.0) / std::max(scale, 1e-300);
            // A fixed CG budget is a deliberate partial solve, which is not
            // dissipative: measured, never failed (as fail_on_unconverged).
            const bool partial = scene.integrator == Integrator::SemiImplicit && scene.solver.cg_fixed_iterations > 0 &&
                                 scene.solver.linear_solver == LinearSolver::CG;
            if (!partial && !std::isfinite(excess)) {
                // State finite but its energy not (|u| ~ 1e300 under a huge
                // load): say so rather than print a NaN ratio.
                const index_t vertex = fastest_vertex();
                double umax = 0;
                for (const S x : u) umax = std::max(umax, std::abs(double(x)));
                throw StepFailure{"step " + std::to_string(step + 1) +
                                      ": the energy is no longer finite (displacements up to " + sci(umax) +
                                      " m): the state left the range of floating point; fastest vertex " +
                                      std::to_string(vertex) + " (check the loads, the units and dt)",
                                  vertex};
            }
            if (!partial && !(excess <= (limit - 1) * scale + noise)) {
                const index_t vertex = fastest_vertex();
                char ratio[48], lim[32];
                std::snprintf(ratio, sizeof ratio, "+%.3g x", excess / std::max(scale, 1e-300));
                std::snprintf(lim, sizeof lim, "%g", limit);
                // From rest (no kinetic or elastic energy yet) a ratio means
                // nothing (it printed +6e288 x): give the gain itself.
                const bool from_rest = !(excess < 1e12 * scale);
                throw StepFailure{"step " + std::to_string(step + 1) + ": energy grew without a source: " +
                                      (from_rest ? "a gain of " + sci(excess) +
                                                       " J net of the external work, by a body that had no kinetic or "
                                                       "elastic energy to speak of (" + sci(scale) + " J)"
                                                 : std::string(ratio) +
                                                       " the largest kinetic + elastic energy seen (a gain of " +
                                                       sci(excess) +
                                                       " J net of the external work since its lowest level; largest " +
                                                       sci(scale) + " J)") +
                                      ", over solver.max_energy_growth = " + lim + "; fastest vertex " +
                                      std::to_string(vertex) +
                                      " (unstable: reduce dt, use the implicit integrator or improve the mesh's worst tets)",
                                  vertex};
            }
            excess = std::max(0.0, excess);
        }
        if (constraints_moved) stats.energy_growth = 1 + excess / std::max(scale, 1e-300);
        energy_excess = excess;
        energy_scale = std::max(scale, end.kinetic + end.elastic - excess);
    }

    // The vertex with the largest speed (for messages).
    index_t fastest_vertex() const {
        index_t best = 0;
        double top = -1;
        for (std::size_t vtx = 0; vtx < mass.size(); ++vtx) {
            const double s2 = double(v[3 * vtx]) * double(v[3 * vtx]) + double(v[3 * vtx + 1]) * double(v[3 * vtx + 1]) +
                              double(v[3 * vtx + 2]) * double(v[3 * vtx + 2]);
            if (s2 > top) {
                top = s2;
                best = index_t(vtx);
            }
        }
        return best;
    }

    void check_finite(long step_no) const {
        // First non-finite dof, found block-parallel.
        const std::size_t chunks = vector_blocks(n());
        std::vector<std::size_t> first(chunks, n());
        for_blocks(*exec, n(), [&](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i)
                if (!std::isfinite(double(u[i])) || !std::isfinite(double(v[i]))) {
                    first[lo / kVectorBlock] = i;
                    break;
                }
        });
        const std::size_t bad = *std::min_element(first.begin(), first.end());
        if (bad < n()) {
            const std::size_t i = bad;
            throw StepFailure{"step " + std::to_string(step_no) + ": non-finite " +
                                      (std::isfinite(double(u[i])) ? "velocity" : "displacement") + " at vertex " +
                                      std::to_string(i / 3) + " (unstable: reduce dt or use an implicit integrator)",
                                  index_t(i / 3)};
        }
    }

    // Constrained velocities that reach the targets at time t_end.
    void constrained_velocities(double T, double t_end, double* vel) const {
        const double s = ramp(t_end);
        for (std::size_t k = 0; k < con_vertex.size(); ++k)
            for (int r = 0; r < 3; ++r) {
                const std::size_t i = 3 * std::size_t(con_vertex[k]) + r;
                vel[i] = (s * con_disp[k][r] - double(u[i])) / T;
            }
    }

    void explicit_step(double T) {
        start_forces();
        external(1.0);
        const double damp = 1 + T * scene.rayleigh_alpha;
        each([&](std::size_t i) { x[i] = (double(v[i]) + T * (h[i] - double(f[i])) / mass[i / 3]) / damp; });
        constrained_velocities(T, time + T, x.data());
        each([&](std::size_t i) {
            v[i] = S(x[i]);
            u[i] += S(T * x[i]);
        });
    }

    void semi_implicit_step(double T) {
        start_forces();
        external(1.0);
        const double c_m = 1 + T * scene.rayleigh_alpha, c_k = T * scene.rayleigh_beta + T * T;
        each([&](std::size_t i) {
            b[i] = mass[i / 3] * double(v[i]) + T * (h[i] - double(f[i]));
            x[i] = double(v[i]);  // warm start
        });
        constrained_velocities(T, time + T, x.data());
        // Reuse K while the interval allows and the step size is the one it
        // was built for (a halved step changes the system matrix).
        const bool reuse = stiffness_age > 0 && stiffness_age < scene.solver.stiffness_interval && T == stiffness_dt;
        const CgResult res =
            solve(c_m, c_k, 0.0, scene.solver.cg_tolerance, scene.solver.definite_stiffness, reuse, scene.solver.cg_fixed_iterations);
        stiffness_age = reuse ? stiffness_age + 1 : 1;
        stiffness_dt = T;
        stats.residual = res.residual;
        if (!std::isfinite(res.residual))
            throw StepFailure{"step " + std::to_string(step + 1) + ": linear solve failed (non-finite residual)", -1};
        if (!res.converged && scene.solver.cg_fixed_iterations == 0 && scene.solver.linear_solver == LinearSolver::CG) {
            ++stats.unconverged_solves;
            if (scene.solver.fail_on_unconverged)
                throw StepFailure{"step " + std::to_string(step + 1) + ": CG stopped at " +
                                      std::to_string(res.iterations) + " iterations with relative residual " +
                                      sci(res.residual) + " above the tolerance " + sci(scene.solver.cg_tolerance),
                                  -1};
        }
        each([&](std::size_t i) {
            v[i] = S(x[i]);
            u[i] += S(T * x[i]);
        });
    }

    // Newton on the incremental potential. Static when T == 0: then the
    // potential is W - load h.u and there is no inertia or damping.
    void newton(double T, const std::vector<double>& u0, const std::vector<double>& upred) {
        const bool dynamic = T > 0;
        const double c_m = dynamic ? 1 / (T * T) + scene.rayleigh_alpha / T : 0.0;
        const double c_b = dynamic ? scene.rayleigh_beta / T : 0.0;
        const auto& sv = scene.solver;
        std::vector<double> R(n()), du(n()), trial(n()), K0d(n()), inertia(n());

        // Potential, its magnitude (sum of the terms' sizes: its round-off
        // is ~1e-14 of that) and the residual at the current u (u, f updated).
        auto evaluate = [&](double& phi, double& scale, double& mag) {
            const double W = forces(true);
            newton_W = W;
            phi = W;
            mag = std::abs(W);
            std::vector<double>& d = newton_d;
            d.resize(n());
            each([&](std::size_t i) { d[i] = double(u[i]) - (dynamic ? u0[i] : 0.0); });
            if (c_b != 0) multiply(*op_damp, d.data(), K0d.data());
            // Per block: R and the inertia terms, and the sums of h.u, |h u|,
            // the kinetic terms and their sizes.
            const std::array<double, 4> sums = blocked_sums<4>(*exec, n(), [&](std::size_t lo, std::size_t hi) {
                std::array<double, 4> acc{};
                for (std::size_t i = lo; i < hi; ++i) {
                    double r = double(f[i]) - h[i];
                    acc[0] += h[i] * double(u[i]);
                    acc[1] += std::abs(h[i] * double(u[i]));
                    inertia[i] = 0;
                    if (dynamic) {
                        const double m = mass[i / 3], e = double(u[i]) - upred[i];
                        inertia[i] = m * e / (T * T) + scene.rayleigh_alpha * m * d[i] / T + c_b * K0d[i];
                        r += inertia[i];
                        const double kin = 0.5 * m * e * e / (T * T) +
                                           0.5 * scene.rayleigh_alpha * m * d[i] * d[i] / T + 0.5 * c_b * d[i] * K0d[i];
                        acc[2] += kin;
                        acc[3] += std::abs(kin);
                    }
                    R[i] = free_dof[i] ? r : 0.0;
                }
                return acc;
            });
            phi += sums[2] - sums[0];
            mag += sums[1] + sums[3];
            scale = scaled_norm(*exec, n(), [&](std::size_t i) { return double(f[i]); }) +
                    scaled_norm(*exec, n(), [&](std::size_t i) { return h[i]; }) +
                    scaled_norm(*exec, n(), [&](std::size_t i) { return inertia[i]; });
        };
        auto norm = [&](const std::vector<double>& a) {
            return scaled_norm(*exec, n(), [&](std::size_t i) { return a[i]; });
        };
        // du.R: its sign from the scaled sum (the value may underflow).
        auto slope_of = [&](bool& descent) {
            const Scaled sl =
                scaled_dot(*exec, n(), [&](std::size_t i) { return x[i]; }, [&](std::size_t i) { return R[i]; });
            descent = sl.mant < 0;
            return sl.value();
        };

        // The residual cannot fall below the round-off of S: a float model
        // is converged at ~1e-5 whatever the scene asks.
        const double tolerance = std::max(sv.newton_tolerance, 100 * double(std::numeric_limits<S>::epsilon()));
        // Forces near the smallest normal number of S (a body whose motion
        // has decayed to ~1e-300 m) have no relative precision left: a
        // residual below that is zero.
        const double underflow = std::sqrt(double(n())) * double(std::numeric_limits<S>::min());
        // Round-off floor. Each force component sums per-edge terms that can
        // be far larger than their sum (stiff materials, slivers, a
        // compressed body), so round-off leaves a residual that can lie
        // above the tolerance. Newton stagnating there is converged:
        //  (b) the relative residual is at most sqrt(eps) and two iterations
        //      in a row did not halve the best one (near a solution a Newton
        //      step gains orders of magnitude: what it cannot reduce is
        //      noise), or the line search cannot reduce it either;
        //  (c) the Newton step is below the resolution of u itself
        //      (|du| <= 8 eps |u|) and the residual did not halve, or the
        //      line search cannot reduce it: no iteration can change the
        //      state any more. (At equilibrium under no load the net forces
        //      vanish while their terms do not: the relative residual there
        //      can be large and is still noise.)
        // docs/scenes.md, "Solver settings".
        const double eps = double(std::numeric_limits<S>::epsilon());
        const double floor_tolerance = std::sqrt(eps);
        double best = INFINITY;
        int stalled = 0;
        auto at_floor = [&] {
            if (stats.residual > floor_tolerance) return false;
            stats.newton_round_off = true;
            return true;
        };
        double phi = 0, scale = 0, mag = 0;
        evaluate(phi, scale, mag);
        for (int it = 0;; ++it) {
            const double rn = norm(R);
            stats.residual = scale > 0 ? rn / scale : rn;
            if (!std::isfinite(rn))
                throw StepFailure{"step " + std::to_string(step + 1) + ": non-finite residual in Newton", -1};
            if (rn <= tolerance * scale || rn <= underflow) return;
            stalled = stats.residual > 0.5 * best ? stalled + 1 : 0;
            best = std::min(best, stats.residual);
            if (stalled >= 2 && at_floor()) return;
            if (it == sv.newton_max_iterations)
                throw StepFailure{"step " + std::to_string(step + 1) + ": Newton did not converge in " +
                                      std::to_string(sv.newton_max_iterations) + " iterations (relative residual " +
                                      sci(stats.residual) + ")",
                                  -1};
            ++stats.newton_iterations;
            // Solve (c_m M + K + c_b K0) du = -R, du = 0 on constrained dofs.
            each([&](std::size_t i) {
                b[i] = -R[i];
                x[i] = 0;
            });
            const double eta = std::min(1e-2, std::max(1e-12, rn / std::max(scale, 1e-300)));
            solve(c_m, 1.0, c_b, eta, sv.definite_stiffness);
            bool descent = false, newton_direction = true;
            double slope = slope_of(descent);
            if (!descent || !std::isfinite(slope)) {  // not a descent direction: use the definite K
                if (scene.method == Method::Edge) {
                    each([&](std::size_t i) { x[i] = 0; });
                    solve_once(c_m, 1.0, c_b, eta, true);
                    slope = slope_of(descent);
                }
                if (!descent) {  // last resort: scaled gradient
                    newton_direction = false;
                    each([&](std::size_t i) { x[i] = -R[i] / (mass[i / 3] * std::max(c_m, 1.0)); });
                    slope = slope_of(descent);
                }
            }
            copy_state(du, x);
            each([&](std::size_t i) { trial[i] = double(u[i]); });
            const bool below_resolution = newton_direction && norm(du) <= 8 * eps * norm(trial);
            if (below_resolution && stalled >= 1) {  // (c)
                stats.newton_round_off = true;
                return;
            }
            // Backtracking line search: Armijo on the potential while it can
            // resolve the decrease asked for; below ~1e4 x its round-off (near
            // the solution, or at tiny steps) the potential's differences are
            // noise and the residual norm is the merit instead (du is a
            // descent direction for it too).
            double step_len = 1, phi_new = 0, scale_new = 0, mag_new = 0;
            for (int ls = 0;; ++ls) {
                each([&](std::size_t i) { u[i] = S(trial[i] + step_len * du[i]); });
                evaluate(phi_new, scale_new, mag_new);
                if (std::isfinite(phi_new)) {
                    const double decrease = -1e-4 * step_len * slope;
                    if (decrease > 1e-10 * mag) {
                        if (phi_new <= phi - decrease) break;
                    } else if (norm(R) <= (1 - 1e-4 * step_len) * rn) {
                        break;
                    }
                }
                if (ls == 40) {
                    each([&](std::size_t i) { u[i] = S(trial[i]); });
                    evaluate(phi, scale, mag);  // back to the iterate (and its f, W)
                    if (at_floor()) return;     // (b)
                    if (below_resolution) {     // (c)
                        stats.newton_round_off = true;
                        return;
                    }
                    throw StepFailure{"step " + std::to_string(step + 1) +
                                          ": line search failed: neither the potential nor the residual decreases "
                                          "along the Newton direction (Newton iteration " + std::to_string(it + 1) +
                                          ", relative residual " + sci(stats.residual) + ", directional slope " +
                                          sci(slope) + ")",
                                      -1};
                }
                step_len *= 0.5;
            }
            phi = phi_new;
            scale = scale_new;
            mag = mag_new;
        }
    }

    void implicit_step(double T) {
        external(1.0);
        std::vector<double> u0(n()), upred(n());
        each([&](std::size_t i) {
            u0[i] = double(u[i]);
            upred[i] = u0[i] + T * double(v[i]);
        });
        if (scene.rayleigh_beta > 0) {
            if (!op_damp) op_damp = factory(scene.mesh, scene.materials, scene.model, scene.method);
            std::vector<S> scratch(n());
            op_damp->forces(u.data(), scratch.data(), false);
            op_damp->build_stiffness(scene.solver.definite_stiffness);
        }
        // Start from the prediction with the constrained dofs at their targets.
        const double s = ramp(time + T);
        each([&](std::size_t i) { u[i] = S(upred[i]); });
        for (std::size_t k = 0; k < con_vertex.size(); ++k)
            for (int r = 0; r < 3; ++r) u[3 * std::size_t(con_vertex[k]) + r] = S(s * con_disp[k][r]);
        newton(T, u0, upred);
        each([&](std::size_t i) { v[i] = S((double(u[i]) - u0[i]) / T); });
    }

    void advance(double T, int depth) {
        // The state is saved only when a failed step may be retried (the
        // whole step's start is kept by do_step).
        const bool may_retry = depth < scene.solver.max_step_halvings;
        // Depth 0 restores the step's start, which do_step has just saved.
        std::vector<S> u_save, v_save;
        if (may_retry && depth > 0) {
            u_save = u;
            v_save = v;
        }
        try {
            forces_current = false;
            const bool guard = scene.solver.max_energy_growth > 0;
            EnergySample start;
            bool moved = false;
            if (guard) {
                moved = constraints_move(time + T);
                start = energy_at_start();
            }
            switch (scene.integrator) {
                case Integrator::Explicit: explicit_step(T); break;
                case Integrator::SemiImplicit: semi_implicit_step(T); break;
                case Integrator::Implicit: implicit_step(T); break;
            }
            check_finite(step + 1);
            // Implicit: Newton's last evaluation was at the new u. Else the
            // force pass here is the one the next step starts with.
            if (guard) check_energy(T, start, scene.integrator == Integrator::Implicit ? newton_W : forces(true), moved);
            time += T;
        } catch (const StepFailure& failure) {
            forces_current = false;
            if (!may_retry) throw;
            if (depth == 0) {
                copy_state(u, step_start_u);
                copy_state(v, step_start_v);
            } else {
                u = u_save;
                v = v_save;
            }
            ++stats.halvings;
            advance(T / 2, depth + 1);
            advance(T / 2, depth + 1);
        }
    }

    const StepStats& do_step() {
        stats = StepStats{};
        const double t_start = time;
        // The state before the step, restored when it fails: a failed step
        // left its rejected (often exploded) state behind, and a later step
        // or energies() went on from it as if nothing had happened.
        // Persistent buffers: one copy per step, no allocation.
        copy_state(step_start_u, u);
        copy_state(step_start_v, v);
        try {
            advance(scene.dt, 0);
        } catch (const StepFailure& failure) {
            time = t_start;
            u.assign(step_start_u.begin(), step_start_u.end());
            v.assign(step_start_v.begin(), step_start_v.end());
            forces_current = false;
            throw SimulationError(failure.message, step + 1, failure.vertex);
        }
        time = t_start + scene.dt;  // no drift from summed halves
        ++step;
        if (scene.count_inverted_tets) stats.inverted_tets = op->inverted_tets(u.data());
        return stats;
    }

    StaticResult do_static() {
        each([&](std::size_t i) { v[i] = S(0); });
        if (con_vertex.empty())
            throw InvalidArgument("static equilibrium needs fixed or prescribed vertices (else it is singular)");
        stats = StepStats{};
        StaticResult result;
        const std::vector<double> none;
        // The increment halves on a failure, at most 12 times over the whole
        // solve. (A budget of 12 per load step, with increments that never
        // grow back, was tried: past a buckling point it ran for minutes on
        // a 96-tet bar, thousands of tiny increments each failing anew.)
        double done = 0, inc = 1.0 / scene.solver.load_steps;
        int halvings = 0;
        std::vector<S> u_save;
        while (done < 1 - 1e-15) {
            const double load = std::min(1.0, done + inc);
            copy_state(u_save, u);
            external(load);
            for (std::size_t k = 0; k < con_vertex.size(); ++k)
                for (int r = 0; r < 3; ++r) u[3 * std::size_t(con_vertex[k]) + r] = S(load * con_disp[k][r]);
            try {
                newton(0.0, none, none);
            } catch (const StepFailure& failure) {
                copy_state(u, u_save);
                if (++halvings > 12)
                    throw SimulationError("static solve: load fraction " + fmt_load(done) + " -> " + fmt_load(load) + ": " +
                                              failure.message + " even with load increment " + sci(inc) +
                                              " (after 12 halvings)",
                                          step, failure.vertex);
                inc /= 2;
                continue;
            }
            done = load;
            ++result.load_steps;
        }
        // The targets are reached: later steps hold them there instead of
        // restarting the ramp from time 0 (which pulled the prescribed
        // vertices back to rest at 100x their speed).
        ramp_floor = 1;
        result.newton_iterations = stats.newton_iterations;
        result.residual = stats.residual;
        result.converged = true;
        if (scene.count_inverted_tets) stats.inverted_tets = op->inverted_tets(u.data());
        check_finite(step);
        return result;
    }

    Energies energies() {
        Energies e;
        e.elastic = op->energy(u.data());
        for (std::size_t i = 0; i < n(); ++i) {
            const double m = mass[i / 3];
            e.kinetic += 0.5 * m * double(v[i]) * double(v[i]);
            e.gravity -= m * scene.gravity[i % 3] * (scene.mesh.X[i] + double(u[i]));
        }
        return e;
    }
};

template <class S>
Simulator<S>::Simulator(Scene scene, std::shared_ptr<const Executor> executor, OperatorFactory<S> factory)
    : impl_(std::make_unique<Impl>(std::move(scene), std::move(executor), std::move(factory))) {}
template <class S>
Simulator<S>::~Simulator() = default;
template <class S>
typename Simulator<S>::Impl& Simulator<S>::self() const {
    if (!impl_) throw Error("Simulator: used after it was moved from");
    return *impl_;
}
template <class S>
Simulator<S>::Simulator(Simulator&&) noexcept = default;
template <class S>
Simulator<S>& Simulator<S>::operator=(Simulator&&) noexcept = default;

template <class S>
const Scene& Simulator<S>::scene() const {
    return self().scene;
}
template <class S>
index_t Simulator<S>::num_vertices() const {
    return self().scene.mesh.num_vertices();
}
template <class S>
const StepStats& Simulator<S>::step() {
    return self().do_step();
}
template <class S>
StaticResult Simulator<S>::solve_static() {
    try {
        return self().do_static();
    } catch (const StepFailure& failure) {
        throw SimulationError("static solve: " + failure.message, self().step, failure.vertex);
    }
}
template <class S>
std::span<S> Simulator<S>::displacement() {
    return self().u;
}
template <class S>
std::span<S> Simulator<S>::velocity() {
    return self().v;
}
template <class S>
std::span<S> Simulator<S>::external_forces() {
    return self().fext;
}
template <class S>
std::span<const S> Simulator<S>::forces() const {
    return self().f;
}
template <class S>
std::span<const double> Simulator<S>::lumped_mass() const {
    return self().mass;
}
template <class S>
std::vector<double> Simulator<S>::positions() const {
    std::vector<double> x(self().n());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = self().scene.mesh.X[i] + double(self().u[i]);
    return x;
}
template <class S>
Energies Simulator<S>::energies() {
    return self().energies();
}
template <class S>
long Simulator<S>::step_index() const {
    return self().step;
}
template <class S>
double Simulator<S>::time() const {
    return self().time;
}
template <class S>
const StepStats& Simulator<S>::last_stats() const {
    return self().stats;
}

template class Simulator<double>;
template class Simulator<float>;

}  // namespace edgefem
