#include "cuda/device_vector_kernels.cuh"

namespace edgefem::cuda {

template <class S>
void DeviceVectorKernels<S>::system_diagonal_range(std::size_t lo, std::size_t hi, double c_m, double c_k,
                                                   double c_b, const double* mass_dof, const double* in,
                                                   const double* K0in, double* out) const {
    this->launch_.each(hi - lo, [=] __device__(std::size_t k) {
        UnifiedVectorKernels<S, DeviceLaunch>::diagonal_range(lo + k, lo + k + 1, c_m, c_k, c_b, mass_dof, in, K0in,
                                                              out);
    });
}

template <class S>
void DeviceVectorKernels<S>::block_jacobi_apply_range(std::size_t lo, std::size_t hi, const double* Dinv,
                                                      const double* r, double* z) const {
    const std::size_t v0 = lo / 3;
    this->launch_.each(hi / 3 - v0, [=] __device__(std::size_t k) {
        const std::size_t v = v0 + k;
        ops::block_jacobi_apply(&Dinv[9 * v], &r[3 * v], &z[3 * v]);
    });
}

template <class S>
CgResult DeviceVectorKernels<S>::cg(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof,
                                    const double* b, double* x, std::size_t n, const CgSettings& settings,
                                    CgWork& w) const {
    const auto start = this->cg_start(A, M, free_dof, b, x, n, w);
    const CgControl control(settings, start.bnorm);
    CgResult res;
    res.residual = control.residual(start.rr);
    if (control.converged(res.residual)) {  // as cg_iterations
        res.converged = true;
        return res;
    }
    CgDeviceState init;
    init.rz = start.rz;
    init.residual = res.residual;
    init.stopped = res.residual == 0;
    CgDeviceState* st = cg_state_.data();
    check(cudaMemcpy(st, &init, sizeof init, cudaMemcpyHostToDevice), "cudaMemcpy (CG state)");
    double* r = w.r.data();
    double* z = w.z.data();
    double* p = w.p.data();
    double* Ap = w.Ap.data();
    const double* keep = w.keep.data();
    const bool fixed = settings.fixed_iterations > 0;
    const double tolerance = control.tolerance();
    const double scale = control.scale();
    const int limit = control.limit(), every = fixed ? limit : kCgCheckEvery;
    CgDeviceState out = init;
    for (int it = 0; it < limit && !out.stopped; ++it) {
        this->cg_apply(A, p, Ap, n);
        this->launch_.sum_then(
            n, [=] __device__(std::size_t i) { return p[i] * Ap[i] * keep[i]; },
            [=] __device__(double pAp) {
                if (st->stopped) return;
                if (!CgControl::positive_curvature(pAp)) {
                    st->negative = 1;
                    st->stopped = 1;
                    return;
                }
                st->alpha = CgControl::alpha(st->rz, pAp);
            });
        this->launch_.sum_then(
            n,
            [=] __device__(std::size_t i) {
                if (st->stopped) return 0.0;
                x[i] += st->alpha * p[i];
                r[i] = (r[i] - st->alpha * Ap[i]) * keep[i];
                return r[i] * r[i];
            },
            [=] __device__(double rr) {
                if (st->stopped) return;
                ++st->iterations;
                st->residual = CgControl::relative(rr, scale);
                // cg_iterations: stop when converged, or before an iteration on a zero residual.
                if ((!fixed && st->residual <= tolerance) || st->residual == 0) st->stopped = 1;
            });
        M.apply(0, n, r, z);
        this->launch_.sum_then(
            n, [=] __device__(std::size_t i) { return st->stopped ? 0.0 : r[i] * z[i] * keep[i]; },
            [=] __device__(double rz) {
                if (st->stopped) return;
                st->beta = CgControl::beta(rz, st->rz);
                st->rz = rz;
            });
        this->launch_.each(n, [=] __device__(std::size_t i) {
            if (!st->stopped) p[i] = (z[i] + st->beta * p[i]) * keep[i];
        });
        if ((it + 1) % every == 0 || it + 1 == limit)
            check(cudaMemcpy(&out, st, sizeof out, cudaMemcpyDeviceToHost), "cudaMemcpy (CG state)");
    }
    res.iterations = out.iterations;
    res.residual = out.residual;
    res.negative_curvature = out.negative != 0;
    res.converged = !res.negative_curvature && res.residual <= tolerance;
    return res;
}

template class DeviceVectorKernels<double>;
template class DeviceVectorKernels<float>;

}  // namespace edgefem::cuda
