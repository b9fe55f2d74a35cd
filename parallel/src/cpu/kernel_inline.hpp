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

// EDGEFEM_SCALAR_LOOP marks an out-of-line range loop that must stay scalar.
// With restrict pointers in scope, g++ 12 vectorises the edge loop of
// edge_strain_range (the vertex loads as scalar loads and inserts), which
// ran 1.6x slower than the scalar loop (bunny-4k: 6.1 against 3.7 ns/tet).
#if defined(__GNUC__) && !defined(__clang__)
#define EDGEFEM_SCALAR_LOOP __attribute__((noinline, optimize("no-tree-vectorize")))
#elif defined(__clang__)
#define EDGEFEM_SCALAR_LOOP __attribute__((noinline))
#else
#define EDGEFEM_SCALAR_LOOP
#endif

// EDGEFEM_LOOP marks an out-of-line batch loop: its own function keeps the
// code around it as compiled without it (a second, prefetching copy of the
// g pass inlined next to the plain one made the plain one 7 % slower on
// bunny-4k).
#if defined(__GNUC__) || defined(__clang__)
#define EDGEFEM_LOOP __attribute__((noinline))
#else
#define EDGEFEM_LOOP
#endif
