// Preconditioned conjugate gradients on a projected system: constrained
// degrees of freedom keep the value they have in x on entry, the others solve
// P A P x = P b. Matrix-free: A and the preconditioner are callables. The
// vector updates run as fixed blocks on the executor and dot products sum
// per-block partials in block order: bitwise the same for any thread count.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "edgefem/core/executor.hpp"

namespace edgefem {

struct CgResult {
    int iterations = 0;
    double residual = 0;  // |P(b - A x)| / |P b| at exit (|P b| = 0: absolute)
    bool converged = false;
    bool negative_curvature = false;  // met p^T A p <= 0: stopped at the last good iterate
};

struct CgWork {
    std::vector<double> r, z, p, Ap;  // double: the iteration's recurrences stay accurate for float A
    std::vector<double> keep;         // 1 on unknowns, 0 on constrained dofs
};

// n scalars; free_dof[i] != 0 for unknowns. apply_A(const double* x, double* y)
// overwrites y = A x; apply_M(const double* r, double* z) overwrites
// z = M^-1 r. `fixed_iterations` > 0 runs exactly that many iterations
// (unless the residual vanishes), ignoring the tolerance.
template <class ApplyA, class ApplyM>
CgResult conjugate_gradient(const Executor& ex, std::size_t n, const std::uint8_t* free_dof, ApplyA&& apply_A,
                            ApplyM&& apply_M, const double* b, double* x, double tolerance, int max_iterations,
                            int fixed_iterations, CgWork& w) {
    w.r.resize(n);
    w.z.resize(n);
    w.p.resize(n);
    w.Ap.resize(n);
    w.keep.resize(n);
    auto dot = [&](const std::vector<double>& a, const std::vector<double>& c) {
        return blocked_sum(ex, n, [&](std::size_t i) { return a[i] * c[i]; });
    };
    // The projection multiplies by keep (1 or 0) inside the passes: g++ 12
    // vectorises none of these loops with a select on free_dof in them.
    // A p is not projected in a pass of its own (p is zero on constrained
    // dofs: p.Ap takes keep in its terms and r in its update), nor is z (r
    // is zero there: r.z takes keep, and p in its update). Scalars by value
    // and arrays through local restrict pointers, so that the loops
    // vectorise.
    double* __restrict r = w.r.data();
    double* __restrict z = w.z.data();
    double* __restrict p = w.p.data();
    double* __restrict Ap = w.Ap.data();
    double* __restrict keep = w.keep.data();
    for_blocks(ex, n, [=](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) keep[i] = free_dof[i] ? 1.0 : 0.0;
    });
    const double bnorm = std::sqrt(blocked_sum(ex, n, [=](std::size_t i) { return b[i] * b[i] * keep[i]; }));
    const double scale = bnorm > 0 ? bnorm : 1.0;

    // (Fusing each vector update into the dot product after it, one pass
    // instead of two, measured 3 % slower per step on armadillo-7k: the
    // updates no longer vectorise inside blocked_sum's 4-lane sums.)
    apply_A(x, Ap);
    for_blocks(ex, n, [=](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) r[i] = (b[i] - Ap[i]) * keep[i];
    });
    CgResult res;
    res.residual = std::sqrt(dot(w.r, w.r)) / scale;
    const int limit = fixed_iterations > 0 ? fixed_iterations : max_iterations;
    if (fixed_iterations == 0 && res.residual <= tolerance) {
        res.converged = true;
        return res;
    }
    apply_M(r, z);
    for_blocks(ex, n, [=](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) p[i] = z[i] * keep[i];
    });
    double rz = dot(w.r, w.p);
    for (int it = 0; it < limit; ++it) {
        if (res.residual == 0) break;
        apply_A(p, Ap);
        const double pAp = blocked_sum(ex, n, [=](std::size_t i) { return p[i] * Ap[i] * keep[i]; });
        if (!(pAp > 0)) {  // also catches NaN
            res.negative_curvature = true;
            break;
        }
        const double alpha = rz / pAp;
        double* __restrict xs = x;
        for_blocks(ex, n, [=](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) {
                xs[i] += alpha * p[i];
                r[i] = (r[i] - alpha * Ap[i]) * keep[i];
            }
        });
        ++res.iterations;
        res.residual = std::sqrt(dot(w.r, w.r)) / scale;
        if (fixed_iterations == 0 && res.residual <= tolerance) break;
        apply_M(r, z);
        const double rz_new = blocked_sum(ex, n, [=](std::size_t i) { return r[i] * z[i] * keep[i]; });
        const double beta = rz_new / rz;
        rz = rz_new;
        for_blocks(ex, n, [=](std::size_t lo, std::size_t hi) {
            for (std::size_t i = lo; i < hi; ++i) p[i] = (z[i] + beta * p[i]) * keep[i];
        });
    }
    res.converged = !res.negative_curvature && res.residual <= tolerance;
    return res;
}

}  // namespace edgefem
