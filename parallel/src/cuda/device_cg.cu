#include "cuda/device_cg.cuh"

namespace edgefem::cuda {

CgResult device_cg(const DeviceLaunch& launch, CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof,
                   const double* b, double* x, std::size_t n, const CgSettings& settings, CgWork& w) {
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

    // As conjugate_gradient (cg.hpp): residuals relative to |P(b - A x_c)|.
    const bool moving = launch.sum(n, [=] __device__(std::size_t i) {
                            return double(int(free_dof[i] == 0) & int(x[i] != 0));
                        }) > 0;
    double bnorm = 0;
    if (moving) {
        launch.each(n, [=] __device__(std::size_t i) { z[i] = free_dof[i] ? 0.0 : x[i]; });
        apply_A(z, Ap);
        bnorm = std::sqrt(launch.sum(n, [=] __device__(std::size_t i) {
            const double d = (b[i] - Ap[i]) * (free_dof[i] ? 1.0 : 0.0);
            return d * d;
        }));
    }
    apply_A(x, Ap);
    const double bb = launch.sum(n, [=] __device__(std::size_t i) {
        keep[i] = free_dof[i] ? 1.0 : 0.0;
        r[i] = (b[i] - Ap[i]) * keep[i];
        return b[i] * b[i] * keep[i];
    });
    if (!moving) bnorm = std::sqrt(bb);
    const double rr0 = launch.sum(n, [=] __device__(std::size_t i) { return r[i] * r[i]; });
    M.apply(0, n, r, z);
    const double rz0 = launch.sum(n, [=] __device__(std::size_t i) {
        p[i] = z[i] * keep[i];
        return r[i] * p[i];
    });
    const CgControl control(settings, bnorm);
    return cg_iterations(control, rr0, rz0, [&](double rz) {
        CgSums s;
        apply_A(p, Ap);
        s.pAp = launch.sum(n, [=] __device__(std::size_t i) { return p[i] * Ap[i] * keep[i]; });
        if (!CgControl::positive_curvature(s.pAp)) return s;
        const double alpha = CgControl::alpha(rz, s.pAp);
        s.rr = launch.sum(n, [=] __device__(std::size_t i) {
            x[i] += alpha * p[i];
            r[i] = (r[i] - alpha * Ap[i]) * keep[i];
            return r[i] * r[i];
        });
        M.apply(0, n, r, z);
        s.rz = launch.sum(n, [=] __device__(std::size_t i) { return r[i] * z[i] * keep[i]; });
        if (control.converged(control.residual(s.rr))) return s;
        const double beta = CgControl::beta(s.rz, rz);
        launch.each(n, [=] __device__(std::size_t i) { p[i] = (z[i] + beta * p[i]) * keep[i]; });
        return s;
    });
}

}  // namespace edgefem::cuda
