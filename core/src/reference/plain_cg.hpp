// The reference back-end's cg kernel: CG as plain whole-vector passes in
// index order, one after another, with cg.hpp's scalar steps and loop.
#pragma once

#include "edgefem/core/cg.hpp"

namespace edgefem {

inline CgResult plain_cg(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof, const double* b,
                         double* x, std::size_t n, const CgSettings& settings, CgWork& w) {
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
    const auto apply_A = [&](const double* in, double* out) {
        A.products(in, out);
        A.finish(0, n, in, out);
    };
    const auto dot = [&](const double* a, const double* c, bool masked) {
        double s = 0;
        for (std::size_t i = 0; i < n; ++i) s += a[i] * c[i] * (masked ? keep[i] : 1.0);
        return s;
    };
    for (std::size_t i = 0; i < n; ++i) keep[i] = free_dof[i] ? 1.0 : 0.0;
    // Residuals are relative to |P(b - A x_c)|, x_c: x's constrained values.
    bool moving_constraints = false;
    for (std::size_t i = 0; i < n; ++i) moving_constraints = moving_constraints || (!free_dof[i] && x[i] != 0);
    double bb = 0;
    if (moving_constraints) {
        for (std::size_t i = 0; i < n; ++i) z[i] = free_dof[i] ? 0.0 : x[i];
        apply_A(z, Ap);
        for (std::size_t i = 0; i < n; ++i) r[i] = (b[i] - Ap[i]) * keep[i];
        bb = dot(r, r, false);
    } else {
        bb = dot(b, b, true);
    }
    apply_A(x, Ap);
    for (std::size_t i = 0; i < n; ++i) r[i] = (b[i] - Ap[i]) * keep[i];
    M.apply(0, n, r, z);
    for (std::size_t i = 0; i < n; ++i) p[i] = z[i] * keep[i];
    const CgControl control(settings, std::sqrt(bb));
    return cg_iterations(control, dot(r, r, false), dot(r, p, false), [&](double rz) {
        apply_A(p, Ap);
        const double pAp = dot(p, Ap, true);
        if (!CgControl::positive_curvature(pAp)) return CgSums{pAp, 0, 0};
        const double alpha = CgControl::alpha(rz, pAp);
        for (std::size_t i = 0; i < n; ++i) {
            x[i] += alpha * p[i];
            r[i] = (r[i] - alpha * Ap[i]) * keep[i];
        }
        M.apply(0, n, r, z);
        const CgSums sums{pAp, dot(r, r, false), dot(r, z, true)};
        if (!control.converged(control.residual(sums.rr))) {
            const double beta = CgControl::beta(sums.rz, rz);
            for (std::size_t i = 0; i < n; ++i) p[i] = (z[i] + beta * p[i]) * keep[i];
        }
        return sums;
    });
}

}  // namespace edgefem
