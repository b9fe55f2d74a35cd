// The element-wise bodies of the vector kernels (vector_kernels.hpp), each
// formula written once here and shared by every back-end: plain functions
// of scalars (or of one vertex's values), usable on the host and, under
// nvcc, on a device. The loops around them are the back-ends' own.
#pragma once

#include <cmath>
#include <cstddef>

#include "edgefem/physics/host_device.hpp"

namespace edgefem::ops {

// The larger of a and b; a when they are unordered (as std::max).
EDGEFEM_HOST_DEVICE inline double max2(double a, double b) { return a < b ? b : a; }

// External load per dof: load (m g + f_ext).
EDGEFEM_HOST_DEVICE inline double external_load(double load, double m, double g, double fext) {
    return load * (m * g + fext);
}

// Symplectic Euler's new velocity: (v + T (h - f) / m) / damp, damp = 1 +
// T alpha.
EDGEFEM_HOST_DEVICE inline double explicit_velocity(double v, double T, double h, double f, double m, double damp) {
    return (v + T * (h - f) / m) / damp;
}

// Linearised backward Euler's right-hand side: m v + T (h - f).
EDGEFEM_HOST_DEVICE inline double semi_implicit_rhs(double m, double v, double T, double h, double f) {
    return m * v + T * (h - f);
}

// The velocity that takes a constrained dof from u to `fraction` of its
// displacement `disp` in T.
EDGEFEM_HOST_DEVICE inline double constrained_velocity(double fraction, double disp, double u, double T) {
    return (fraction * disp - u) / T;
}

// a + s b (a prediction u0 + T v, a line-search point u + step du).
EDGEFEM_HOST_DEVICE inline double axpy(double a, double s, double b) { return a + s * b; }

// Backward Euler's velocity (u - u0) / T.
EDGEFEM_HOST_DEVICE inline double difference_quotient(double u, double u0, double T) { return (u - u0) / T; }

// The diagonal part of A = c_m M + c_k K + c_b K0 applied to x, added to
// the product y = K x: c_m m x + c_k y.
EDGEFEM_HOST_DEVICE inline double system_diagonal(double c_m, double m, double x, double c_k, double y) {
    return c_m * m * x + c_k * y;
}

// Newton's residual at one dof of the incremental potential (newton.hpp):
// r = f - h + inertia on the free dofs, and the kinetic part of the
// potential; e = u - upred, d = u - ud, K0d = (K0 d) at the dof. The
// scheme's coefficients: c_i on the inertia (1 / T^2 for backward Euler),
// c_d on the damping (1 / T).
struct NewtonTerms {
    double r = 0, inertia = 0, kinetic = 0;
};
EDGEFEM_HOST_DEVICE inline NewtonTerms newton_terms(bool dynamic, double f, double h, double u, double m, double upred,
                                                    double d, double K0d, double c_i, double c_d, double alpha,
                                                    double c_b) {
    NewtonTerms t;
    t.r = f - h;
    if (dynamic) {
        const double e = u - upred;
        t.inertia = c_i * m * e + c_d * alpha * m * d + c_b * K0d;
        t.r += t.inertia;
        t.kinetic = 0.5 * c_i * m * e * e + 0.5 * c_d * alpha * m * d * d + 0.5 * c_b * d * K0d;
    }
    return t;
}

// The second-order integrators' predictions (integrators/implicit_step.hpp):
// c0 u + c1 v + c2 h1 + c3 h2 from the state and two history values.
EDGEFEM_HOST_DEVICE inline double history_combination(double c0, double c1, double c2, double c3, double u, double v,
                                                       double h1, double h2) {
    return c0 * u + c1 * v + c2 * h1 + c3 * h2;
}

// The load of an implicit scheme at one dof: (c_h h + c_r r + c_a m a) /
// (m if per_mass, else 1), with r = h - f - alpha m v - beta K0v the
// unbalanced force at the step's start (an acceleration: m a = r;
// generalized-alpha's load: its weighted start terms).
EDGEFEM_HOST_DEVICE inline double dynamic_load(double h, double f, double v, double a, double K0v, double m,
                                               double alpha, double beta, double c_h, double c_r, double c_a,
                                               bool per_mass) {
    const double r = h - f - alpha * m * v - beta * K0v;
    const double out = c_h * h + c_r * r + c_a * m * a;
    return per_mass ? out / m : out;
}

// Velocity Verlet's half kick: (v (1 - t alpha_e) + t (h - f) / m) / (1 + t
// alpha_i), t = T / 2: mass damping explicit in the first half, implicit in
// the second (together the trapezoidal rule, second order).
EDGEFEM_HOST_DEVICE inline double verlet_kick(double v, double t, double h, double f, double m, double alpha_e,
                                              double alpha_i) {
    return (v * (1 - t * alpha_e) + t * (h - f) / m) / (1 + t * alpha_i);
}

// One vertex's twice kinetic energy m |v|^2 and gravity work m g.u.
EDGEFEM_HOST_DEVICE inline double kinetic_term(double m, double vx, double vy, double vz) {
    return m * (vx * vx + vy * vy + vz * vz);
}
EDGEFEM_HOST_DEVICE inline double gravity_term(double m, double g0, double g1, double g2, double ux, double uy,
                                               double uz) {
    return m * (g0 * ux + g1 * uy + g2 * uz);
}

// One dof's mass-damping work over a step, divided by alpha: m du . v_d,
// with v_d = w_new v' + w_old v the velocity the step's damping force acts
// at (TimeIntegrator::damping_account).
EDGEFEM_HOST_DEVICE inline double damping_work_term(double m, double du, double v_new, double v_old, double w_new,
                                                    double w_old) {
    return m * du * (w_new * v_new + w_old * v_old);
}

// Inverse of the symmetric part of B (row-major into inv) by Cholesky;
// false when it is not positive definite. Written out for 3x3: Eigen's LLT
// solve against the identity went through its general triangular solver
// and made the block-Jacobi set-up ~5% of a semi-implicit step.
EDGEFEM_HOST_DEVICE inline bool spd_inverse3(const double (&B)[3][3], double* inv) {
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

// Block-Jacobi at one vertex: the inverse of its 3x3 diagonal block B =
// c_k D + c_b D0 + c_m m I of A (D, D0: the blocks of K and K0, row-major;
// D0 is read only when c_b != 0); a block that is not positive definite
// falls back to its mass part, so the preconditioner stays SPD.
template <class S>
EDGEFEM_HOST_DEVICE inline void block_jacobi_inverse(const S* D, const S* D0, double m, double c_m, double c_k,
                                                     double c_b, double* inv) {
    double B[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            B[i][j] = c_k * double(D[3 * i + j]) + (c_b != 0 ? c_b * double(D0[3 * i + j]) : 0.0) +
                      (i == j ? c_m * m : 0.0);
    if (!spd_inverse3(B, inv)) {
        const double d = max2(max2(max2(max2(c_m * m, B[0][0]), B[1][1]), B[2][2]), 1e-300);
        for (int i = 0; i < 9; ++i) inv[i] = (i % 4 == 0) ? 1 / d : 0.0;
    }
}

// z = Minv r at one vertex (Minv: its 3x3 inverse, exactly symmetric by
// spd_inverse3, so its rows are its columns). On the host as rows times
// broadcasts in 4-lane vectors: lane 3 reads the value after the block
// (the inverses' array has one spare at the end) and is never stored.
EDGEFEM_HOST_DEVICE inline void block_jacobi_apply(const double* Minv, const double* r, double* z) {
#if defined(__CUDA_ARCH__) || !defined(__GNUC__)
    for (int i = 0; i < 3; ++i) z[i] = r[0] * Minv[i] + r[1] * Minv[3 + i] + r[2] * Minv[6 + i];
#else
    typedef double V4 __attribute__((vector_size(32)));
    V4 m0, m1, m2;
    __builtin_memcpy(&m0, Minv, sizeof m0);
    __builtin_memcpy(&m1, Minv + 3, sizeof m1);
    __builtin_memcpy(&m2, Minv + 6, sizeof m2);
    const V4 zv = r[0] * m0 + r[1] * m1 + r[2] * m2;
    for (int i = 0; i < 3; ++i) z[i] = zv[i];
#endif
}

}  // namespace edgefem::ops
