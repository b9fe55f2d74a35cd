// Marks for code that host and device compilers both build.
//   EDGEFEM_HOST_DEVICE: __host__ __device__ under nvcc, nothing for a host
//     compiler (MFEM's MFEM_HOST_DEVICE).
//   EDGEFEM_FORMULA: a per-item formula of physics/: host and device, and
//     always inlined into the loop that calls it (g++ stops inlining in large
//     translation units, and a call per edge cost a force pass 30 %).
//   EDGEFEM_LAMBDA: a lambda a loop body of either compiler may run, written
//     [=] EDGEFEM_LAMBDA (args) { ... }: nvcc's extended __host__ __device__
//     lambda (--extended-lambda), nothing for a host compiler.
//   EDGEFEM_UNROLL(n): unroll the next loop n times where the compiler
//     takes the hint (g++'s and nvcc's pragmas; clang unrolls on its own).
#pragma once

#if defined(__CUDACC__) || defined(__HIPCC__)
#define EDGEFEM_HOST_DEVICE __host__ __device__
#else
#define EDGEFEM_HOST_DEVICE
#endif

#if defined(__CUDACC__) || defined(__HIPCC__)
#define EDGEFEM_LAMBDA __host__ __device__
#else
#define EDGEFEM_LAMBDA
#endif

#if defined(__CUDACC__) || defined(__HIPCC__)
#define EDGEFEM_FORMULA EDGEFEM_HOST_DEVICE __forceinline__
#elif defined(__GNUC__) || defined(__clang__)
#define EDGEFEM_FORMULA inline __attribute__((always_inline))
#else
#define EDGEFEM_FORMULA inline
#endif

#define EDGEFEM_PRAGMA(x) _Pragma(#x)
#if defined(__CUDACC__) || defined(__HIPCC__)
#define EDGEFEM_UNROLL(n) EDGEFEM_PRAGMA(unroll n)
#elif defined(__GNUC__) && !defined(__clang__)
#define EDGEFEM_UNROLL(n) EDGEFEM_PRAGMA(GCC unroll n)
#else
#define EDGEFEM_UNROLL(n)
#endif
