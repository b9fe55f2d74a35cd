// The vector kernels (vector_kernels.hpp) on the device: the unified bodies
// (unified/unified_vector_kernels.hpp, CG included) on DeviceLaunch's loops,
// and the *_range kernels as launches over their range.
#pragma once

#include "cuda/device_launch.cuh"
#include "unified/unified_vector_kernels.hpp"

namespace edgefem::cuda {

template <class S>
class DeviceVectorKernels final : public UnifiedVectorKernels<S, DeviceLaunch> {
public:
    DeviceVectorKernels() : UnifiedVectorKernels<S, DeviceLaunch>(DeviceLaunch{}) {}

    void system_diagonal_range(std::size_t lo, std::size_t hi, double c_m, double c_k, double c_b,
                               const double* mass_dof, const double* in, const double* K0in,
                               double* out) const override;
    void block_jacobi_apply_range(std::size_t lo, std::size_t hi, const double* Dinv, const double* r,
                                  double* z) const override;
};

extern template class DeviceVectorKernels<double>;
extern template class DeviceVectorKernels<float>;

}  // namespace edgefem::cuda
