// The NVIDIA GPU back-end: model data, state vectors, K blocks and the
// solvers' vectors live on the device; one step runs there without copying
// a vector to or from the host (CG's scalars stay on the device; other
// reductions bring one scalar back). Scatters
// are gathers over adjacency lists and reductions run in an order fixed by
// the problem size, so two runs on the same GPU give the same bits.
//
// Built when CMake finds nvcc >= 12 (option EDGEFEM_CUDA, AUTO by default);
// in a build without it, or on a machine without a usable GPU,
// make_cuda_backend throws Error with the reason.
#pragma once

#include <memory>
#include <string>

#include "edgefem/core/backend.hpp"
#include "edgefem/core/error.hpp"

namespace edgefem {

// Whether this build has the CUDA back-end.
bool cuda_built();
// Empty when the CUDA back-end can run here; else why not (no CUDA in this
// build, no device, a driver error).
std::string cuda_unavailable_reason();
// "NVIDIA H100 80GB HBM3 (sm_90, driver 13.0)" or similar; empty when
// unavailable.
std::string cuda_device_description();

// How the back-end runs what has more than one form.
struct CudaOptions {
    // The edge operators' K x: `multiply_lanes` threads per vertex (1, 4 or
    // 8) pull the terms of its edges, summed in a fixed order (the same bits
    // on every run); 0: one thread per edge adds its terms into the result
    // with floating-point atomics (the last bits change from run to run).
    // Measured in docs/gpu.md.
    int multiply_lanes = 8;
};

// Throws InvalidArgument naming the option that is out of range.
inline void validate(const CudaOptions& o) {
    const int l = o.multiply_lanes;
    if (l != 0 && l != 1 && l != 4 && l != 8)
        throw InvalidArgument("CudaOptions::multiply_lanes is " + std::to_string(l) + ", expected 0, 1, 4 or 8");
}

// The back-end on the current CUDA device. Throws Error naming the reason
// when it cannot run, InvalidArgument for options out of range.
template <class S>
std::shared_ptr<const Backend<S>> make_cuda_backend(const CudaOptions& options = {});

}  // namespace edgefem
