// Every vector kernel (vector_kernels.hpp), written once over a
// back-end's loops (a Launch) with the formulas of vector_ops.hpp. A Launch
// provides:
//   each(n, body(i)), each_vertex(n, body(v)) over n dofs' vertices,
//   blocks(n, body(lo, hi)): the dofs in the launch's blocks,
//   sum(n, term(i)) -> double, in an order fixed by n,
//   range_sum(lo, hi, term(i)) -> double (static), within one block,
//   reduce(n, init, block(lo, hi) -> R, combine(R&, const R&)) -> R: the
//   blocks' results combined in block order.
// The reference back-end's launch is plain serial loops over one block
// (reference/serial_launch.hpp), the CPU back-end's fixed blocks on an
// Executor (cpu/blocked_launch.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "edgefem/core/vector_kernels.hpp"
#include "edgefem/core/vector_ops.hpp"

namespace edgefem {

template <class S, class Launch>
class UnifiedVectorKernels : public VectorKernels<S> {
public:
    explicit UnifiedVectorKernels(Launch launch) : launch_(std::move(launch)) {}

    void fill(double* x, std::size_t n, double value) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { x[i] = value; });
    }
    void fill_state(S* x, std::size_t n, S value) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { x[i] = value; });
    }
    void copy(double* dst, const double* src, std::size_t n) const override { copy_any(dst, src, n); }
    void copy_state(S* dst, const S* src, std::size_t n) const override { copy_any(dst, src, n); }
    void to_state(S* dst, const double* src, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { dst[i] = S(src[i]); });
    }
    void from_state(double* dst, const S* src, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { dst[i] = double(src[i]); });
    }
    void rescale(double* a, double* b, std::size_t n, double s, bool divide) const override {
        if (divide)
            launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
                a[i] /= s;
                b[i] /= s;
            });
        else
            launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
                a[i] *= s;
                b[i] *= s;
            });
    }

    void external_load(double* h, const S* fext, const double* mass, const std::array<double, 3>& g, double load,
                       std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { h[i] = ops::external_load(load, mass[i / 3], g[i % 3], double(fext[i])); });
    }
    void explicit_velocity(double* x, const S* v, const double* h, const S* f, const double* mass, double T,
                           double damp, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            x[i] = ops::explicit_velocity(double(v[i]), T, h[i], double(f[i]), mass[i / 3], damp);
        });
    }
    void semi_implicit_rhs(double* b, double* x, const S* v, const double* h, const S* f, const double* mass,
                           double T, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            b[i] = ops::semi_implicit_rhs(mass[i / 3], double(v[i]), T, h[i], double(f[i]));
            x[i] = double(v[i]);
        });
    }
    void take_velocity(S* u, S* v, const double* x, double T, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            v[i] = S(x[i]);
            u[i] += S(T * x[i]);
        });
    }
    void velocity_change(double* d, double* v_prev, const S* v, const std::uint8_t* free_dof,
                         std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            const double now = double(v[i]);
            d[i] = free_dof[i] ? now - v_prev[i] : 0.0;
            v_prev[i] = now;
        });
    }
    void free_part(double* d, const double* x, const std::uint8_t* free_dof, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { d[i] = free_dof[i] ? x[i] : 0.0; });
    }
    void axpby(double* y, double a, const double* x, double c, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { y[i] = a * x[i] + c * y[i]; });
    }
    std::array<double, 3> warm_start_sums(const double* d, const double* b, const double* x, const double* Ad,
                                          std::size_t n) const override {
        return launch_.reduce(
            n, std::array<double, 3>{},
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                std::array<double, 3> acc{};
                for (std::size_t i = lo; i < hi; ++i) {
                    acc[0] += d[i] * b[i];
                    acc[1] += x[i] * Ad[i];
                    acc[2] += d[i] * Ad[i];
                }
                return acc;
            },
            AddArrays{});
    }
    void implicit_predict(double* u0, double* upred, const S* u, const S* v, double T, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            u0[i] = double(u[i]);
            upred[i] = ops::axpy(u0[i], T, double(v[i]));
        });
    }
    void implicit_velocity(S* v, const S* u, const double* u0, double T, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { v[i] = S(ops::difference_quotient(double(u[i]), u0[i], T)); });
    }
    void newton_increment(double* d, const S* u, const double* u0, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { d[i] = double(u[i]) - (u0 ? u0[i] : 0.0); });
    }
    void newton_rhs(double* b, double* x, const double* R, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            b[i] = -R[i];
            x[i] = 0;
        });
    }
    void scaled_gradient(double* x, const double* R, const double* mass, double c, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { x[i] = -R[i] / (mass[i / 3] * c); });
    }
    void line_search_point(S* u, const double* u_start, const double* du, double step, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { u[i] = S(ops::axpy(u_start[i], step, du[i])); });
    }

    void history_predict(double* upred, double* ud, const S* u, const S* v, const double* h1, const double* h2,
                         const std::array<double, 4>& cp, const std::array<double, 4>& cd,
                         std::size_t n) const override {
        const double p0 = cp[0], p1 = cp[1], p2 = cp[2], p3 = cp[3], q0 = cd[0], q1 = cd[1], q2 = cd[2], q3 = cd[3];
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            const double x = double(u[i]), y = double(v[i]), a = h1 ? h1[i] : 0.0, b = h2 ? h2[i] : 0.0;
            upred[i] = ops::history_combination(p0, p1, p2, p3, x, y, a, b);
            ud[i] = ops::history_combination(q0, q1, q2, q3, x, y, a, b);
        });
    }
    void history_update(S* v, double* a, const S* u, const double* upred, const double* ud, const double* cvel,
                        const std::uint8_t* free_dof, double c_v, double c_a, std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            const double x = double(u[i]);
            v[i] = S(free_dof[i] ? c_v * (x - ud[i]) : cvel[i]);
            if (a) a[i] = free_dof[i] ? c_a * (x - upred[i]) : 0.0;
        });
    }
    void dynamic_load(const DynamicLoadArgs<S>& args, std::size_t n) const override {
        const DynamicLoadArgs<S> a = args;
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            a.out[i] = a.free_dof[i] ? ops::dynamic_load(a.h[i], double(a.f[i]), double(a.v[i]),
                                                         a.c_a != 0 ? a.a[i] : 0.0, a.beta != 0 ? a.K0v[i] : 0.0,
                                                         a.mass[i / 3], a.alpha, a.beta, a.c_h, a.c_r, a.c_a,
                                                         a.per_mass)
                                     : 0.0;
        });
    }
    void verlet_kick(double* x, const S* v, const double* h, const S* f, const double* mass,
                     const std::uint8_t* free_dof, double t, double alpha_e, double alpha_i,
                     std::size_t n) const override {
        launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            x[i] = free_dof[i] ? ops::verlet_kick(double(v[i]), t, h[i], double(f[i]), mass[i / 3], alpha_e, alpha_i)
                               : double(v[i]);
        });
    }

    void constrained_velocities(double* vel, const S* u, const ConstraintView& c, double fraction,
                                double T) const override {
        const index_t* vertex = c.vertex;
        const double* disp = c.disp;
        launch_.each(3 * c.count, [=] EDGEFEM_LAMBDA(std::size_t j) {
            const std::size_t i = 3 * std::size_t(vertex[j / 3]) + j % 3;
            vel[i] = ops::constrained_velocity(fraction, disp[j], double(u[i]), T);
        });
    }
    void hold_constraints(S* u, const ConstraintView& c, double fraction) const override {
        const index_t* vertex = c.vertex;
        const double* disp = c.disp;
        launch_.each(3 * c.count, [=] EDGEFEM_LAMBDA(std::size_t j) { u[3 * std::size_t(vertex[j / 3]) + j % 3] = S(fraction * disp[j]); });
    }
    bool constraints_move(const S* u, const ConstraintView& c, double fraction, double tol) const override {
        const index_t* vertex = c.vertex;
        const double* disp = c.disp;
        return launch_.reduce(
            3 * c.count, false,
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                for (std::size_t j = lo; j < hi; ++j) {
                    const double target = fraction * disp[j], cur = double(u[3 * std::size_t(vertex[j / 3]) + j % 3]);
                    if (std::abs(target - cur) > tol * (std::abs(target) + std::abs(cur))) return true;
                }
                return false;
            },
            [] EDGEFEM_LAMBDA(bool& any, bool part) { any = any || part; });
    }

    double count_differences(const S* a, const S* b, std::size_t n) const override {
        return launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) { return a[i] == b[i] ? 0.0 : 1.0; });
    }
    // Per block as interleaved sums over its vertices (a block holds whole
    // vertices). One running sum per term, through the dofs, took 6.5 us
    // per call on bunny-4k (3423 dofs).
    std::array<double, 3> energy_sums(const S* u, const S* v, const S* fext, const double* mass,
                                      const std::array<double, 3>& g, std::size_t n) const override {
        const double g0 = g[0], g1 = g[1], g2 = g[2];
        return launch_.reduce(
            n, std::array<double, 3>{},
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                const std::size_t a0 = lo / 3, a1 = hi / 3;
                const auto d = [](S x) { return double(x); };
                // v read before the call: read as its arguments (evaluated in
                // another order), g++ 12 fused other products into FMAs.
                const double kinetic = Launch::range_sum(a0, a1, [&](std::size_t a) {
                    const double vx = d(v[3 * a]), vy = d(v[3 * a + 1]), vz = d(v[3 * a + 2]);
                    return ops::kinetic_term(mass[a], vx, vy, vz);
                });
                const double gravity = Launch::range_sum(a0, a1, [&](std::size_t a) {
                    return ops::gravity_term(mass[a], g0, g1, g2, d(u[3 * a]), d(u[3 * a + 1]), d(u[3 * a + 2]));
                });
                const double load = Launch::range_sum(lo, hi, [&](std::size_t i) { return d(fext[i]) * d(u[i]); });
                return std::array<double, 3>{0.5 * kinetic, -gravity, load};
            },
            AddArrays{});
    }
    std::array<double, 4> constrained_sums(const S* u, const S* v, const S* fext, const S* f, const S* u_from,
                                           const double* mass, const std::array<double, 3>& g, const ConstraintView& c,
                                           double fraction) const override {
        const double g0 = g[0], g1 = g[1], g2 = g[2];
        const index_t* vertex = c.vertex;
        const double* disp = c.disp;
        return launch_.reduce(
            c.count, std::array<double, 4>{},
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                const auto d = [](S x) { return double(x); };
                std::array<double, 4> s{};
                for (std::size_t k = lo; k < hi; ++k) {
                    const std::size_t a = std::size_t(vertex[k]), i = 3 * a;
                    s[0] += ops::kinetic_term(mass[a], d(v[i]), d(v[i + 1]), d(v[i + 2]));
                    s[1] += ops::gravity_term(mass[a], g0, g1, g2, d(u[i]), d(u[i + 1]), d(u[i + 2]));
                    for (std::size_t j = 0; j < 3; ++j) {
                        s[2] += d(fext[i + j]) * d(u[i + j]);
                        s[3] += d(f[i + j]) * (fraction * disp[3 * k + j] - d(u_from[i + j]));
                    }
                }
                return std::array<double, 4>{0.5 * s[0], -s[1], s[2], s[3]};
            },
            AddArrays{});
    }
    double damping_work(const S* u, const S* u0, const S* v, const S* v0, const double* mass, double w_new,
                        double w_old, std::size_t n) const override {
        return launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            return ops::damping_work_term(mass[i / 3], double(u[i]) - double(u0[i]), double(v[i]), double(v0[i]),
                                          w_new, w_old);
        });
    }
    std::size_t first_non_finite(const S* u, const S* v, std::size_t n) const override {
        return launch_.reduce(
            n, n,
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                for (std::size_t i = lo; i < hi; ++i)
                    if (!std::isfinite(double(u[i])) || !std::isfinite(double(v[i]))) return i;
                return n;
            },
            [] EDGEFEM_LAMBDA(std::size_t& first, std::size_t part) { first = std::min(first, part); });
    }
    Scaled scaled_dot(const double* a, const double* b, std::size_t n) const override {
        return scaled_dot_of([=] EDGEFEM_LAMBDA(std::size_t i) { return a[i]; }, [=] EDGEFEM_LAMBDA(std::size_t i) { return b[i]; }, n);
    }
    double scaled_norm(const double* a, std::size_t n) const override {
        return norm_of(scaled_dot_of([=] EDGEFEM_LAMBDA(std::size_t i) { return a[i]; }, [=] EDGEFEM_LAMBDA(std::size_t i) { return a[i]; }, n));
    }
    double scaled_norm_state(const S* a, std::size_t n) const override {
        const auto term = [=] EDGEFEM_LAMBDA(std::size_t i) { return double(a[i]); };
        return norm_of(scaled_dot_of(term, term, n));
    }
    std::array<double, 4> newton_residual(const NewtonResidualArgs<S>& a, std::size_t n) const override {
        return launch_.reduce(
            n, std::array<double, 4>{},
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                std::array<double, 4> acc{};
                for (std::size_t i = lo; i < hi; ++i) {
                    const double u = double(a.u[i]);
                    const ops::NewtonTerms t = ops::newton_terms(
                        a.dynamic, double(a.f[i]), a.h[i], u, a.mass[i / 3], a.dynamic ? a.upred[i] : 0.0,
                        a.dynamic ? a.d[i] : 0.0, a.dynamic ? a.K0d[i] : 0.0, a.c_i, a.c_d, a.alpha, a.c_b);
                    acc[0] += a.h[i] * u;
                    acc[1] += std::abs(a.h[i] * u);
                    a.inertia[i] = t.inertia;
                    if (a.dynamic) {
                        acc[2] += t.kinetic;
                        acc[3] += std::abs(t.kinetic);
                    }
                    a.R[i] = a.free_dof[i] ? t.r : 0.0;
                }
                return acc;
            },
            AddArrays{});
    }
    std::array<double, 3> solve_magnitudes(const double* b, const double* x, const double* mass_dof,
                                           const std::uint8_t* free_dof, std::size_t n) const override {
        return launch_.reduce(
            n, std::array<double, 3>{},
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                double bm = 0, xm = 0, mm = 0;
                for (std::size_t i = lo; i < hi; ++i) {
                    if (free_dof[i]) bm = std::max(bm, std::abs(b[i]));
                    xm = std::max(xm, std::abs(x[i]));
                    mm = std::max(mm, mass_dof[i]);
                }
                return std::array<double, 3>{bm, xm, mm};
            },
            [] EDGEFEM_LAMBDA(std::array<double, 3>& m, const std::array<double, 3>& p) {
                for (int k = 0; k < 3; ++k) m[k] = std::max(m[k], p[k]);
            });
    }

    void system_diagonal_range(std::size_t lo, std::size_t hi, double c_m, double c_k, double c_b,
                               const double* mass_dof, const double* in, const double* K0in,
                               double* out) const override {
        diagonal_range(lo, hi, c_m, c_k, c_b, mass_dof, in, K0in, out);
    }
    void system_diagonal(std::size_t n, double c_m, double c_k, double c_b, const double* mass_dof, const double* in,
                         const double* K0in, double* out) const override {
        launch_.blocks(n, [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
            diagonal_range(lo, hi, c_m, c_k, c_b, mass_dof, in, K0in, out);
        });
    }
    void block_jacobi_build(double* Dinv, const S* D, const S* D0, const double* mass, double c_m, double c_k,
                            double c_b, std::size_t n) const override {
        launch_.each_vertex(n, [=] EDGEFEM_LAMBDA(std::size_t v) {
            ops::block_jacobi_inverse(D + 9 * v, c_b != 0 ? D0 + 9 * v : nullptr, mass[v], c_m, c_k, c_b,
                                      Dinv + 9 * v);
        });
    }
    void block_jacobi_apply_range(std::size_t lo, std::size_t hi, const double* Dinv, const double* r_in,
                                  double* z_out) const override {
        const double* __restrict r = r_in;
        double* __restrict z = z_out;
        const double* __restrict Minv = Dinv;
        for (std::size_t v = lo / 3; v < hi / 3; ++v) ops::block_jacobi_apply(&Minv[9 * v], &r[3 * v], &z[3 * v]);
    }

    // CG as whole-vector passes, each fusing an update with the sum that
    // follows it (one reduction per sum), with cg.hpp's scalar steps and
    // loop: what the reference back-end (index order) and the CUDA back-end
    // run; the CPU back-end overrides it with its fused three-phase form.
    CgResult cg(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof, const double* b, double* x,
                std::size_t n, const CgSettings& settings, CgWork& w) const override {
        const CgStart start = cg_start(A, M, free_dof, b, x, n, w);
        double* r = w.r.data();
        double* z = w.z.data();
        double* p = w.p.data();
        double* Ap = w.Ap.data();
        const double* keep = w.keep.data();
        const CgControl control(settings, start.bnorm);
        return cg_iterations(control, start.rr, start.rz, [&](double rz) {
            CgSums s;
            cg_apply(A, p, Ap, n);
            s.pAp = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) { return p[i] * Ap[i] * keep[i]; });
            if (!CgControl::positive_curvature(s.pAp)) return s;
            const double alpha = CgControl::alpha(rz, s.pAp);
            s.rr = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
                x[i] += alpha * p[i];
                r[i] = (r[i] - alpha * Ap[i]) * keep[i];
                return r[i] * r[i];
            });
            M.apply(0, n, r, z);
            s.rz = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) { return r[i] * z[i] * keep[i]; });
            if (control.converged(control.residual(s.rr))) return s;
            const double beta = CgControl::beta(s.rz, rz);
            launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { p[i] = (z[i] + beta * p[i]) * keep[i]; });
            return s;
        });
    }

    // The helpers below are public only because nvcc's extended lambdas
    // may not sit in a private or protected member function.

    // out = A in, both parts.
    static void cg_apply(CgSystem& A, const double* in, double* out, std::size_t n) {
        A.products(in, out);
        A.finish(0, n, in, out);
    }
    // CG's start pass: r = P(b - A x), z = M^-1 r, p = z; the norm the
    // residuals are relative to, r.r and r.z.
    struct CgStart {
        double bnorm = 0, rr = 0, rz = 0;
    };
    CgStart cg_start(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof, const double* b, double* x,
                     std::size_t n, CgWork& w) const {
        w.r.resize(n);
        w.z.resize(n);
        w.p.resize(n);
        w.Ap.resize(n);
        w.keep.resize(n);
        double* r = w.r.data();
        double* z = w.z.data();
        double* p = w.p.data();
        double* Ap = w.Ap.data();
        double* keep = w.keep.data();
        const auto apply_A = [&](const double* in, double* out) { cg_apply(A, in, out, n); };

        // As conjugate_gradient (cg.hpp): residuals relative to |P(b - A x_c)|.
        const bool moving = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
                                return double(int(free_dof[i] == 0) & int(x[i] != 0));
                            }) > 0;
        double bnorm = 0;
        if (moving) {
            launch_.each(n, [=] EDGEFEM_LAMBDA(std::size_t i) { z[i] = free_dof[i] ? 0.0 : x[i]; });
            apply_A(z, Ap);
            bnorm = std::sqrt(launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
                const double d = (b[i] - Ap[i]) * (free_dof[i] ? 1.0 : 0.0);
                return d * d;
            }));
        }
        apply_A(x, Ap);
        const double bb = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            keep[i] = free_dof[i] ? 1.0 : 0.0;
            r[i] = (b[i] - Ap[i]) * keep[i];
            return b[i] * b[i] * keep[i];
        });
        if (!moving) bnorm = std::sqrt(bb);
        const double rr0 = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) { return r[i] * r[i]; });
        M.apply(0, n, r, z);
        const double rz0 = launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) {
            p[i] = z[i] * keep[i];
            return r[i] * p[i];
        });
        return {bnorm, rr0, rz0};
    }
    template <class T>
    void copy_any(T* dst, const T* src, std::size_t n) const {
        launch_.blocks(n, [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) dst[i] = src[i];
        });
    }
    // Element-wise sums of arrays (reduce's combine).
    struct AddArrays {
        template <std::size_t K>
        EDGEFEM_HOST_DEVICE void operator()(std::array<double, K>& s, const std::array<double, K>& p) const {
            for (std::size_t k = 0; k < K; ++k) s[k] += p[k];
        }
    };
    // Scalars by value and the arrays through local restrict pointers: the
    // loops vectorise.
    EDGEFEM_HOST_DEVICE static void diagonal_range(std::size_t lo, std::size_t hi, double c_m, double c_k, double c_b,
                               const double* mass_dof, const double* in, const double* K0in, double* out) {
        const double* __restrict m = mass_dof;
        const double* __restrict xin = in;
        double* __restrict y = out;
        for (std::size_t i = lo; i < hi; ++i) y[i] = ops::system_diagonal(c_m, m[i], xin[i], c_k, y[i]);
        if (c_b != 0) {
            const double* __restrict a = K0in;
            for (std::size_t i = lo; i < hi; ++i) y[i] += c_b * a[i];
        }
    }
    // The exponent of the largest |term(i)| and the last non-finite term
    // (0 if none). A maximum is exact in any order.
    template <class Term>
    std::array<double, 2> max_exponent(Term term, std::size_t n) const {
        const std::array<double, 2> m = launch_.reduce(
            n, std::array<double, 2>{},
            [=] EDGEFEM_LAMBDA(std::size_t lo, std::size_t hi) {
                double mx = 0, b = 0;
                for (std::size_t i = lo; i < hi; ++i) {
                    const double t = std::abs(term(i));
                    if (!std::isfinite(t)) b = t;
                    mx = std::max(mx, t);
                }
                return std::array<double, 2>{mx, b};
            },
            [] EDGEFEM_LAMBDA(std::array<double, 2>& acc, const std::array<double, 2>& p) {
                if (p[1] != 0) acc[1] = p[1];
                acc[0] = std::max(acc[0], p[0]);
            });
        return {m[0] > 0 ? double(std::ilogb(m[0])) : 0.0, m[1]};
    }
    template <class A, class B>
    Scaled scaled_dot_of(A a, B b, std::size_t n) const {
        const std::array<double, 2> xa = max_exponent(a, n), xb = max_exponent(b, n);
        const double bad = xb[1] != 0 ? xb[1] : xa[1];
        if (bad != 0) return {bad, 0};
        const int ea = int(xa[0]), eb = int(xb[0]);
        return {launch_.sum(n, [=] EDGEFEM_LAMBDA(std::size_t i) { return std::ldexp(a(i), -ea) * std::ldexp(b(i), -eb); }), ea + eb};
    }
    static double norm_of(const Scaled& s) {
        return std::isfinite(s.mant) ? std::ldexp(std::sqrt(s.mant), s.exp / 2) : s.mant;
    }

protected:
    Launch launch_;
};

}  // namespace edgefem
