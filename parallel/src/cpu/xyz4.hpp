// A vertex's xyz (or a 3x3 block's row) in the first three lanes of a
// 4-lane GCC/Clang vector: the edge and per-tet kernels' unit of SIMD work
// for built-in scalars.
#pragma once

namespace edgefem::kernel {

// One vertex's xyz as the first three lanes of a 4-lane vector (lane 3
// zero), and back: two loads / stores that never touch the next vertex.
template <class S>
struct Xyz4 {
    typedef S V __attribute__((vector_size(4 * sizeof(S))));
    static V load(const S* p) {
        V v = {p[0], p[1], p[2], S(0)};
        return v;
    }
    static void store(S* p, V v) {
        p[0] = v[0];
        p[1] = v[1];
        p[2] = v[2];
    }
    // Row r of a row-major 3x3 block as lanes 0..2 (lane 3 reads the next
    // value: K blocks are followed by a sink block, so it is in bounds, and
    // it only ever meets a zero lane).
    static V row(const S* k) {
        V v;
        __builtin_memcpy(&v, k, sizeof v);
        return v;
    }
    // All 4 lanes to p[0..3]: for rows written in address order, where the
    // next row's store overwrites lane 3.
    static void put(S* p, V v) { __builtin_memcpy(p, &v, sizeof v); }
};

}  // namespace edgefem::kernel
