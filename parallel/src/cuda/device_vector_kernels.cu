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

template class DeviceVectorKernels<double>;
template class DeviceVectorKernels<float>;

}  // namespace edgefem::cuda
