// The vector kernels (vector_kernels.hpp) on the device: the unified bodies
// (unified/unified_vector_kernels.hpp, CG included) on DeviceLaunch's loops,
// and the *_range kernels as launches over their range. CG's iterations
// keep their scalars on the device (CgDeviceState): the same arithmetic as
// the unified CG, with no wait for the host inside the iterations.
#pragma once

#include "cuda/device_launch.cuh"
#include "unified/unified_vector_kernels.hpp"

namespace edgefem::cuda {

// CG's scalars between its passes, in device memory.
struct CgDeviceState {
    double rz = 0, alpha = 0, beta = 0, residual = 0;
    int iterations = 0, stopped = 0, negative = 0, pad = 0;
};

template <class S>
class DeviceVectorKernels final : public UnifiedVectorKernels<S, DeviceLaunch> {
public:
    DeviceVectorKernels() : UnifiedVectorKernels<S, DeviceLaunch>(DeviceLaunch{}), cg_state_(1) {}

    // The unified CG's start pass, then its iterations with alpha, beta and
    // the stopping tests on the device (the same operations, so the same
    // bits): the host launches the passes without waiting and reads the
    // state back every kCgCheckEvery iterations (once at the end for a
    // fixed count). Iterations launched after the device stopped change
    // nothing but the work vectors.
    CgResult cg(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof, const double* b, double* x,
                std::size_t n, const CgSettings& settings, CgWork& w) const override;
    static constexpr int kCgCheckEvery = 4;

    void system_diagonal_range(std::size_t lo, std::size_t hi, double c_m, double c_k, double c_b,
                               const double* mass_dof, const double* in, const double* K0in,
                               double* out) const override;
    void block_jacobi_apply_range(std::size_t lo, std::size_t hi, const double* Dinv, const double* r,
                                  double* z) const override;

private:
    mutable DeviceArray<CgDeviceState> cg_state_;
};

extern template class DeviceVectorKernels<double>;
extern template class DeviceVectorKernels<float>;

}  // namespace edgefem::cuda
