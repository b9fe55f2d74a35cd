// Preconditioned CG on the device: cg.hpp's scalar steps and iteration loop
// (CgControl, cg_iterations) around passes that each fuse an update with
// the dot product that follows it (one kernel and one scalar back to the
// host per sum). The system's products and the preconditioner run as the
// whole-vector calls of CgSystem and CgPreconditioner (on [0, n)).
#pragma once

#include "cuda/device_launch.cuh"
#include "edgefem/core/cg.hpp"

namespace edgefem::cuda {

CgResult device_cg(const DeviceLaunch& launch, CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof,
                   const double* b, double* x, std::size_t n, const CgSettings& settings, CgWork& w);

}  // namespace edgefem::cuda
