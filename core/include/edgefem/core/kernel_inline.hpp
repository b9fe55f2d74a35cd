// EDGEFEM_KERNEL marks the per-item kernels (one edge, one segment) that the
// serial and parallel loops call once per item. GCC stops inlining in large
// translation units (elastic_operator.cpp hit its unit-growth limit), and a
// call per edge cost edge_strain 30 % of a bunny-4k force call: the loops
// only run at speed with these bodies inlined.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define EDGEFEM_KERNEL inline __attribute__((always_inline))
#else
#define EDGEFEM_KERNEL inline
#endif
