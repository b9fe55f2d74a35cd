// The vector kernels the Simulator's integrators and solvers run, declared
// once: every back-end implements them on its own memory (BackendVector
// data, n dofs = 3 #V unless said). The reference back-end (core/src/
// reference) runs plain serial loops in index order and is the oracle the
// tests compare against; the CPU back-end (core/src/cpu) runs fixed blocks
// on an Executor, with the same results for any thread count. The
// element-wise formulas are vector_ops.hpp's. Kernels named *_range run on
// the calling thread over [lo, hi) (inside CG's passes); all others may
// run in parallel and return when done.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "edgefem/core/cg.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem {

// A sum of squares or products without underflow, mant x 2^exp: each
// vector is scaled by a power of two near its largest entry first (exact).
// Non-finite when an entry is.
struct Scaled {
    double mant = 0;
    int exp = 0;
    double value() const { return std::ldexp(mant, exp); }
};

// Newton's residual (ops::newton_terms) over all dofs: R (0 on constrained
// dofs) and the inertia terms written, and the sums of h.u, |h u|, the
// kinetic terms and their sizes returned. u0 / upred / d / K0d are read
// only when `dynamic`; c_i, c_d: the scheme's inertia and damping
// coefficients (ops::newton_terms).
template <class S>
struct NewtonResidualArgs {
    double* R;
    double* inertia;
    const S* f;
    const S* u;
    const double* h;
    const double* mass;  // #V
    const double* upred;
    const double* d;
    const double* K0d;
    const std::uint8_t* free_dof;
    bool dynamic;
    double c_i, c_d, alpha, c_b;
};

// The load of an implicit scheme (ops::dynamic_load): out = (c_h h + c_r r +
// c_a m a) / (m if per_mass), 0 on constrained dofs; a and K0v are read only
// when c_a != 0 and beta != 0.
template <class S>
struct DynamicLoadArgs {
    double* out;
    const double* h;
    const S* f;
    const S* v;
    const double* a;
    const double* K0v;
    const double* mass;  // #V
    const std::uint8_t* free_dof;
    double alpha, beta, c_h, c_r, c_a;
    bool per_mass;
};

// The fixed and prescribed vertices: vertex[k] and its final displacement
// disp[3 k .. 3 k + 2], k < count.
struct ConstraintView {
    const index_t* vertex;
    const double* disp;
    std::size_t count;
};

template <class S>
class VectorKernels {
public:
    virtual ~VectorKernels() = default;

    // --- copies and conversions ---
    virtual void fill(double* x, std::size_t n, double value) const = 0;
    virtual void fill_state(S* x, std::size_t n, S value) const = 0;
    virtual void copy(double* dst, const double* src, std::size_t n) const = 0;
    virtual void copy_state(S* dst, const S* src, std::size_t n) const = 0;
    virtual void to_state(S* dst, const double* src, std::size_t n) const = 0;    // dst = S(src)
    virtual void from_state(double* dst, const S* src, std::size_t n) const = 0;  // dst = double(src)
    // a /= s and b /= s (`divide`), else a *= s and b *= s.
    virtual void rescale(double* a, double* b, std::size_t n, double s, bool divide) const = 0;

    // --- the integrators' updates (ops:: formulas) ---
    // h = load (M g + f_ext); mass per vertex.
    virtual void external_load(double* h, const S* fext, const double* mass, const std::array<double, 3>& g,
                               double load, std::size_t n) const = 0;
    virtual void explicit_velocity(double* x, const S* v, const double* h, const S* f, const double* mass, double T,
                                   double damp, std::size_t n) const = 0;
    // b = M v + T (h - f), x = v.
    virtual void semi_implicit_rhs(double* b, double* x, const S* v, const double* h, const S* f,
                                   const double* mass, double T, std::size_t n) const = 0;
    // v = x, u += T x.
    virtual void take_velocity(S* u, S* v, const double* x, double T, std::size_t n) const = 0;
    // The semi-implicit and BDF2 steps' warm-start direction: d = v - v_prev
    // on free dofs, 0 on constrained ones; then v_prev = v.
    virtual void velocity_change(double* d, double* v_prev, const S* v, const std::uint8_t* free_dof,
                                 std::size_t n) const = 0;
    // The linearised Newmark step's warm-start direction: d = x on free
    // dofs, 0 on constrained ones.
    virtual void free_part(double* d, const double* x, const std::uint8_t* free_dof, std::size_t n) const = 0;
    // y = a x + c y.
    virtual void axpby(double* y, double a, const double* x, double c, std::size_t n) const = 0;
    // {d.b, x.Ad, d.Ad}: a warm start's improvement along d (plain sums,
    // in the launch's fixed order).
    virtual std::array<double, 3> warm_start_sums(const double* d, const double* b, const double* x, const double* Ad,
                                                  std::size_t n) const = 0;
    // u0 = u, upred = u0 + T v.
    virtual void implicit_predict(double* u0, double* upred, const S* u, const S* v, double T,
                                  std::size_t n) const = 0;
    // v = (u - u0) / T.
    virtual void implicit_velocity(S* v, const S* u, const double* u0, double T, std::size_t n) const = 0;
    // d = u - u0 (u0 null: d = u).
    virtual void newton_increment(double* d, const S* u, const double* u0, std::size_t n) const = 0;
    // b = -R, x = 0.
    virtual void newton_rhs(double* b, double* x, const double* R, std::size_t n) const = 0;
    // x = -R / (m c).
    virtual void scaled_gradient(double* x, const double* R, const double* mass, double c, std::size_t n) const = 0;
    // u = u_start + step du.
    virtual void line_search_point(S* u, const double* u_start, const double* du, double step,
                                   std::size_t n) const = 0;
    // The second-order integrators (ops::history_combination): upred = cp .
    // (u, v, h1, h2), ud = cd . (u, v, h1, h2); h2 (and h1) may be null
    // when their coefficients are 0.
    virtual void history_predict(double* upred, double* ud, const S* u, const S* v, const double* h1,
                                 const double* h2, const std::array<double, 4>& cp, const std::array<double, 4>& cd,
                                 std::size_t n) const = 0;
    // After their solve: v = c_v (u - ud) on free dofs, cvel on constrained
    // ones; a (when not null) = c_a (u - upred) on free dofs, 0 on
    // constrained ones.
    virtual void history_update(S* v, double* a, const S* u, const double* upred, const double* ud,
                                const double* cvel, const std::uint8_t* free_dof, double c_v, double c_a,
                                std::size_t n) const = 0;
    virtual void dynamic_load(const DynamicLoadArgs<S>& a, std::size_t n) const = 0;
    // Velocity Verlet's half kick (ops::verlet_kick) on free dofs, x = v on
    // constrained ones.
    virtual void verlet_kick(double* x, const S* v, const double* h, const S* f, const double* mass,
                             const std::uint8_t* free_dof, double t, double alpha_e, double alpha_i,
                             std::size_t n) const = 0;

    // --- constraints (over their dofs) ---
    // vel = (fraction disp - u) / T on the constrained dofs.
    virtual void constrained_velocities(double* vel, const S* u, const ConstraintView& c, double fraction,
                                        double T) const = 0;
    // u = fraction disp on the constrained dofs.
    virtual void hold_constraints(S* u, const ConstraintView& c, double fraction) const = 0;
    // Whether some constrained u is off fraction disp by more than tol x
    // (|target| + |u|).
    virtual bool constraints_move(const S* u, const ConstraintView& c, double fraction, double tol) const = 0;

    // --- reductions ---
    // The number of i with a[i] != b[i].
    virtual double count_differences(const S* a, const S* b, std::size_t n) const = 0;
    // {kinetic energy, -g.(M u), f_ext.u}; mass per vertex.
    virtual std::array<double, 3> energy_sums(const S* u, const S* v, const S* fext, const double* mass,
                                              const std::array<double, 3>& g, std::size_t n) const = 0;
    // energy_sums over the constrained vertices only, and the work
    // f.(fraction disp - u_from) of f on their move from u_from to their
    // targets: {kinetic, -g.(M u), f_ext.u, work}.
    virtual std::array<double, 4> constrained_sums(const S* u, const S* v, const S* fext, const S* f, const S* u_from,
                                                   const double* mass, const std::array<double, 3>& g,
                                                   const ConstraintView& c, double fraction) const = 0;
    // Sum over the dofs of m (u - u0) (w_new v + w_old v0) (damping_work_term),
    // mass per vertex: mass damping's work over a step, divided by alpha.
    virtual double damping_work(const S* u, const S* u0, const S* v, const S* v0, const double* mass, double w_new,
                                double w_old, std::size_t n) const = 0;
    // The first i with u[i] or v[i] not finite, n if none.
    virtual std::size_t first_non_finite(const S* u, const S* v, std::size_t n) const = 0;
    virtual Scaled scaled_dot(const double* a, const double* b, std::size_t n) const = 0;
    // |a| without underflow (scaled_dot(a, a)).
    virtual double scaled_norm(const double* a, std::size_t n) const = 0;
    virtual double scaled_norm_state(const S* a, std::size_t n) const = 0;
    virtual std::array<double, 4> newton_residual(const NewtonResidualArgs<S>& a, std::size_t n) const = 0;
    // {max |b| over free dofs, max |x|, max mass_dof}.
    virtual std::array<double, 3> solve_magnitudes(const double* b, const double* x, const double* mass_dof,
                                                   const std::uint8_t* free_dof, std::size_t n) const = 0;

    // --- the linear system and its solver ---
    // out = c_m M in + c_k out (+ c_b K0in) on [lo, hi); mass per dof;
    // K0in read only when c_b != 0.
    virtual void system_diagonal_range(std::size_t lo, std::size_t hi, double c_m, double c_k, double c_b,
                                       const double* mass_dof, const double* in, const double* K0in,
                                       double* out) const = 0;
    // The same over all dofs.
    virtual void system_diagonal(std::size_t n, double c_m, double c_k, double c_b, const double* mass_dof,
                                 const double* in, const double* K0in, double* out) const = 0;
    // Dinv (9 #V) from the diagonal blocks D, D0 (9 #V; D0 read only when
    // c_b != 0) and the mass per vertex (ops::block_jacobi_inverse).
    virtual void block_jacobi_build(double* Dinv, const S* D, const S* D0, const double* mass, double c_m,
                                    double c_k, double c_b, std::size_t n) const = 0;
    // z = Dinv r on [lo, hi) (multiples of 3); Dinv has 9 #V + 1 entries.
    virtual void block_jacobi_apply_range(std::size_t lo, std::size_t hi, const double* Dinv, const double* r,
                                          double* z) const = 0;
    // Preconditioned CG on the free dofs (cg.hpp): x holds the constrained
    // values and the warm start.
    virtual CgResult cg(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof, const double* b,
                        double* x, std::size_t n, const CgSettings& settings, CgWork& work) const = 0;
};

}  // namespace edgefem
