// EDGEFEM_HOST_DEVICE marks functions that run on the host and, compiled
// by nvcc, on a device too: the element-wise bodies every back-end shares.
#pragma once

#if defined(__CUDACC__)
#define EDGEFEM_HOST_DEVICE __host__ __device__
#else
#define EDGEFEM_HOST_DEVICE
#endif
