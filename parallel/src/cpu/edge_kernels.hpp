// The edge-based StVK kernels (formulation.md): per-item workers that read
// the model and write only the item's own outputs or one scatter target, and
// serial loops over them. Parallel back-ends run the same workers over their
// own index ranges. All vectors are xyz-interleaved (3 per vertex).
//
// Input is the displacement u = x - X, not the position: zeta is computed as
// d.(2 r + d) with d = u(V0) - u(V1) and r the rest edge vector, which equals
// |p~|^2 - H without its catastrophic cancellation at small strain.
#pragma once

#include <algorithm>
#include <limits>
#include <type_traits>
#include <vector>

#include "edgefem/core/edge_model.hpp"
#include "cpu/kernel_inline.hpp"
#include "cpu/xyz4.hpp"
#include "edgefem/physics/edge_blocks.hpp"
#include "edgefem/physics/edge_force.hpp"
#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/edge_stiffness.hpp"
#include "edgefem/physics/edge_strain.hpp"
#include "edgefem/physics/tsep_stiffness.hpp"

namespace edgefem {

// Per-edge state of one evaluation: current edge vectors p~, zeta, g.
// g is accumulated in double whatever S is: its terms L(E) zeta and
// L(P) zeta cancel heavily on graded meshes, and a float g doubles the float
// kernels' force error (measured: 1.2e-5 vs 5.5e-6 relative on armadillo-7k,
// test_float_accuracy), for 4 extra bytes per edge.
template <class S>
struct EdgeState {
    std::vector<S> p;       // 3 #E
    std::vector<S> zeta;    // #E
    std::vector<double> g;  // #E
    void resize(index_t num_edges) {
        p.resize(3 * static_cast<std::size_t>(num_edges));
        zeta.resize(num_edges);
        g.resize(num_edges);
    }
};

// Where the per-edge state of edge e sits: at e (EdgeState's mesh-wide
// arrays) or at e & mask (a power-of-two ring, FormRing in
// tet_edge_form.hpp, for force calls that keep no state).
struct EdgeSlot {
    index_t operator()(index_t e) const { return e; }
};
struct RingSlot {
    index_t mask;
    index_t operator()(index_t e) const { return e & mask; }
};

// Per-edge 3x3 blocks K(E) (row-major, 9 per edge) plus one sink block.
template <class S>
struct EdgeStiffness {
    std::vector<S> K;  // 9 (#E + 1)
    // Padded copies of x and y (4 per vertex) for edge_multiply: scratch,
    // so one edge_multiply at a time per EdgeStiffness.
    mutable std::vector<S> x4, y4;
    void resize(index_t num_edges) { K.assign(9 * (static_cast<std::size_t>(num_edges) + 1), S(0)); }
};

namespace kernel {

// Edge loop worker: p~(E), zeta(E) and g(E) = L(E) zeta(E).
// The state goes to slot(e) (EdgeSlot: e).
template <class S, class Slot = EdgeSlot>
EDGEFEM_KERNEL void edge_strain(const EdgeModel<S>& m, const S* __restrict u, index_t e, S* __restrict p,
                        S* __restrict zeta, double* __restrict g, Slot slot = {}) {
    const index_t a = m.edge[e][0], b = m.edge[e][1];
    const S* r = &m.rest[3 * std::size_t(e)];
    S q0, q1, q2;
    const S z = physics::edge_strain(u[3 * a] - u[3 * b], u[3 * a + 1] - u[3 * b + 1], u[3 * a + 2] - u[3 * b + 2], r[0],
                                     r[1], r[2], q0, q1, q2);
    const index_t k = slot(e);
    p[3 * std::size_t(k)] = q0;
    p[3 * std::size_t(k) + 1] = q1;
    p[3 * std::size_t(k) + 2] = q2;
    zeta[k] = z;
    g[k] = physics::own_g(m.LE[e], z);
}

// The edge loop over edges [e0, e1), out of line and scalar
// (EDGEFEM_SCALAR_LOOP says why).
template <class S, class Slot = EdgeSlot>
EDGEFEM_SCALAR_LOOP void edge_strain_range(const EdgeModel<S>& m, const S* __restrict u, index_t e0, index_t e1,
                                           S* __restrict p, S* __restrict zeta, double* __restrict g,
                                           Slot slot = {}) {
#if defined(__clang__)
#pragma clang loop vectorize(disable)
#endif
    for (index_t e = e0; e < e1; ++e) edge_strain(m, u, e, p, zeta, g, slot);
}

// V1 of edge e through a local restrict pointer to the edge list: read
// through m inside a segment loop, g++ reloads the vector's data pointer
// after every store to a target row (it may alias).
template <class S>
EDGEFEM_KERNEL auto second_vertex(const EdgeModel<S>& m) {
    const std::array<index_t, 2>* __restrict edge = m.edge.data();
    return [edge](index_t e) { return edge[e][1]; };
}

// Where the segment kernels below write their forward targets (E1 > e0 of
// a TSEP segment, V1 > a of a vertex segment): targets below `end` in
// `direct` (indexed by target), the others in `spill` (indexed by target -
// end). A segment's targets ascend, so it runs as two loops, the second
// empty unless the segment reaches past `end`: the part boundary of the
// owner-computes parallel variant (forward_spill.hpp); the serial loops
// pass direct_only(out), which never spills.
template <class T>
struct ForwardOut {
    T* direct;
    T* spill;
    index_t end;
};
template <class T>
EDGEFEM_KERNEL ForwardOut<T> direct_only(T* out) {
    return {out, nullptr, std::numeric_limits<index_t>::max()};
}
// The first item of [first, last) whose target goes to the spill buffer
// (last when none). Targets ascend, so only a segment whose last target
// spills needs the scan; the serial loops' direct_only(out) folds the test
// away. Found before the loops so that the main loop has no test in it (a
// test inside measured 25-30 % slower in the latency-bound TSEP loop).
template <class T, class Target>
EDGEFEM_KERNEL index_t spill_start(index_t first, index_t last, Target&& target, const ForwardOut<T>& out) {
    if (out.end == std::numeric_limits<index_t>::max() || last == first || target(last - 1) < out.end) return last;
    index_t mid = first;
    while (target(mid) < out.end) ++mid;
    return mid;
}
// The row of target t (W values per target): in `direct` below `end`, else
// in `spill`.
template <int W, class T>
EDGEFEM_KERNEL T* forward_row(const ForwardOut<T>& out, index_t t) {
    return t < out.end ? out.direct + W * std::size_t(t) : out.spill + W * std::size_t(t - out.end);
}
// body(i, row of target(i)) for i in [first, last), W values per target.
template <int W, class T, class Target, class Body>
EDGEFEM_KERNEL void for_segment(index_t first, index_t last, Target&& target, const ForwardOut<T>& out, Body&& body) {
    const index_t mid = spill_start(first, last, target, out);
    // Two items per trip: segments are short (5-7 edges), and g++ 12 runs
    // the K x segments 10 % faster unrolled (bunny-4k 5.15 -> 4.63 ns per
    // tet, bitwise the same; clang 14 unrolls by 2 on its own).
#pragma GCC unroll 2
    for (index_t i = first; i < mid; ++i) body(i, out.direct + W * std::size_t(target(i)));
    for (index_t i = mid; i < last; ++i) body(i, out.spill + W * std::size_t(target(i) - out.end));
}

// TSEP loop worker for the segment of TSEPs whose first edge is e0: each
// pair adds L(P) zeta(E1) to g(E0) and L(P) zeta(E0) to g(E1). The E1 of a
// segment are distinct and greater than e0, so nothing inside it aliases.
template <class S>
EDGEFEM_KERNEL void tsep_strain_segment(const EdgeModel<S>& m, index_t e0, const S* __restrict zeta, double* __restrict g,
                                const ForwardOut<double>& out) {
    // Written out instead of through for_segment, with the split point found
    // first: this loop is bound by the latency of its g updates, and with a
    // test inside it (or the lambda form) it measured 25-30 % slower
    // (bench_kernels force/edge-fe-3pass, bunny-4k: 94 vs 73 us).
    const index_t first = m.tsep_first[e0], last = m.tsep_first[e0 + 1];
    const index_t mid = spill_start(first, last, [&m](index_t P) { return m.tsep_other[P]; }, out);
    const double z0 = zeta[e0];
    double acc = 0;
    double* __restrict direct = out.direct;
    for (index_t P = first; P < mid; ++P) {
        const index_t e1 = m.tsep_other[P];
        const double L = m.LP[P];
        acc += physics::pair_g(L, double(zeta[e1]));
        direct[e1] += physics::pair_g(L, z0);
    }
    for (index_t P = mid; P < last; ++P) {
        const index_t e1 = m.tsep_other[P];
        const double L = m.LP[P];
        acc += physics::pair_g(L, double(zeta[e1]));
        out.spill[e1 - out.end] += physics::pair_g(L, z0);
    }
    g[e0] += acc;
}
template <class S>
EDGEFEM_KERNEL void tsep_strain_segment(const EdgeModel<S>& m, index_t e0, const S* __restrict zeta, double* __restrict g) {
    tsep_strain_segment(m, e0, zeta, g, direct_only(g));
}

// Edge scatter worker: f(V0) += p~ g, f(V1) -= p~ g.
template <class S>
EDGEFEM_KERNEL void edge_force(const EdgeModel<S>& m, index_t e, const S* __restrict p, const double* __restrict g,
                       S* __restrict f) {
    const index_t a = m.edge[e][0], b = m.edge[e][1];
    for (int r = 0; r < 3; ++r) {
        const S v = physics::edge_force(p[3 * std::size_t(e) + r], S(g[e]));
        f[3 * a + r] += v;
        f[3 * b + r] -= v;
    }
}

// One edge of a segment scatter: p~ g added to V0's sums, subtracted from
// f(V1) at fb. Shared by edge_force_segment and the fused
// tsep_force_segment, which must stay bitwise equal.
template <class S>
EDGEFEM_KERNEL void edge_force_terms(const S* __restrict p, index_t e, S gs, S& acc0, S& acc1, S& acc2, S* fb) {
    const S v0 = physics::edge_force(p[3 * std::size_t(e)], gs), v1 = physics::edge_force(p[3 * std::size_t(e) + 1], gs),
            v2 = physics::edge_force(p[3 * std::size_t(e) + 2], gs);
    acc0 += v0;
    acc1 += v1;
    acc2 += v2;
    fb[0] -= v0;
    fb[1] -= v1;
    fb[2] -= v2;
}

// Edge scatter over the segment of edges whose V0 is `a`: f(a) gets the
// segment's sum from registers (edges are sorted by V0, so a per-edge
// f(V0) += ... would chain stores to one address); each f(V1) -= p~ g.
template <class S, class Slot = EdgeSlot>
EDGEFEM_KERNEL void edge_force_segment(const EdgeModel<S>& m, index_t a, const S* __restrict p, const double* __restrict g,
                               S* __restrict f, const ForwardOut<S>& out, Slot slot = {}) {
    S acc0 = 0, acc1 = 0, acc2 = 0;
    for_segment<3>(m.edge_first[a], m.edge_first[a + 1], second_vertex(m), out, [&](index_t e, S* fb) {
        const index_t k = slot(e);
        edge_force_terms(p, k, S(g[k]), acc0, acc1, acc2, fb);
    });
    f[3 * std::size_t(a)] += acc0;
    f[3 * std::size_t(a) + 1] += acc1;
    f[3 * std::size_t(a) + 2] += acc2;
}
template <class S>
EDGEFEM_KERNEL void edge_force_segment(const EdgeModel<S>& m, index_t a, const S* __restrict p, const double* __restrict g,
                               S* __restrict f) {
    edge_force_segment(m, a, p, g, f, direct_only(f));
}

// The TSEP loop and the edge scatter fused, over the segment of edges whose
// V0 is `a`, for the serial loop: run in ascending a, every TSEP segment
// with a smaller first edge has already added its terms to g(e) when e's own
// segment runs, so g(e) is final right after it and is scattered from a
// register (no g store -> reload in a third pass; same operations in the
// same order as tsep_strain_segment then edge_force_segment: bitwise equal).
// Needs g(E) = L(E) zeta(E) from edge_strain for every edge beforehand.
// Measured against the 3-pass loops in one run (bench_kernels,
// force/edge-fe-3pass, medians of 5): bunny-4k 19.6 -> 18.3 ns/tet double,
// 17.9 -> 17.1 float; armadillo-7k 23.8 -> 23.2 double, 23.7 -> 22.5 float.
// A gather form of g (each edge summing its own and its incoming TSEPs, no
// g read-modify-writes) loads twice per pair and measured ~1.7x slower;
// two accumulators in the segment changed nothing outside the noise.
// Also measured and dropped (2026-11-22, RCM, 1 thread, same runs): the
// pair loop unrolled by 2 (same sum order) ran armadillo-7k 13-15 % faster
// but bunny-250k 9-12 % and box-1200 / bunny-4k 3-5 % slower; the sum over
// zeta(E1) in a loop of its own before the g updates, 1.25-1.4x slower.
template <class S>
EDGEFEM_KERNEL void tsep_force_segment(const EdgeModel<S>& m, index_t a, const S* __restrict p, const S* __restrict zeta,
                               double* __restrict g, S* __restrict f) {
    const index_t* __restrict first = m.tsep_first.data();
    const index_t* __restrict other = m.tsep_other.data();
    const S* __restrict LP = m.LP.data();
    const auto V1 = second_vertex(m);
    S acc0 = 0, acc1 = 0, acc2 = 0;
    for (index_t e = m.edge_first[a]; e < m.edge_first[a + 1]; ++e) {
        const double z0 = zeta[e];
        double s = 0;
        for (index_t P = first[e]; P < first[e + 1]; ++P) {
            const index_t e1 = other[P];
            const double L = LP[P];
            s += physics::pair_g(L, double(zeta[e1]));
            g[e1] += physics::pair_g(L, z0);
        }
        const double ge = g[e] + s;
        g[e] = ge;
        edge_force_terms(p, e, S(ge), acc0, acc1, acc2, f + 3 * std::size_t(V1(e)));
    }
    f[3 * std::size_t(a)] += acc0;
    f[3 * std::size_t(a) + 1] += acc1;
    f[3 * std::size_t(a) + 2] += acc2;
}

// The fused segment for one part of the owner-computes parallel force
// (parallel/forward_spill.hpp): g writes past the part's edges go through
// `gout`, f writes past its vertices through `fout`. An edge that also
// receives g terms from earlier parts' spill windows scatters its partial g
// here, and the rest with edge_force_add once the windows are in (the force
// is linear in g).
template <class S>
EDGEFEM_KERNEL void tsep_force_segment(const EdgeModel<S>& m, index_t a, const S* __restrict p, const S* __restrict zeta,
                               double* __restrict g, S* __restrict f, const ForwardOut<double>& gout,
                               const ForwardOut<S>& fout) {
    S acc0 = 0, acc1 = 0, acc2 = 0;
    for_segment<3>(m.edge_first[a], m.edge_first[a + 1], second_vertex(m), fout,
                   [&](index_t e, S* fb) {
                       tsep_strain_segment(m, e, zeta, g, gout);
                       edge_force_terms(p, e, S(g[e]), acc0, acc1, acc2, fb);
                   });
    f[3 * std::size_t(a)] += acc0;
    f[3 * std::size_t(a) + 1] += acc1;
    f[3 * std::size_t(a) + 2] += acc2;
}

// f(V0) += p~ dg with V0 inside the part, f(V1) -= p~ dg through `fout`:
// the rest of an edge's scatter when its g grew by dg.
template <class S>
EDGEFEM_KERNEL void edge_force_add(const EdgeModel<S>& m, index_t e, const S* __restrict p, double dg, S* __restrict f,
                           const ForwardOut<S>& fout) {
    const index_t a = m.edge[e][0];
    S* fb = forward_row<3>(fout, m.edge[e][1]);
    for (int r = 0; r < 3; ++r) {
        const S v = physics::edge_force(p[3 * std::size_t(e) + r], S(dg));
        f[3 * std::size_t(a) + r] += v;
        fb[r] -= v;
    }
}

// Edge term of the stiffness, physics::edge_stiffness (overwrites K(E));
// `Definite`: g clamped at zero.
template <bool Definite = false, class S>
EDGEFEM_KERNEL void edge_stiffness(const EdgeModel<S>& m, index_t e, const S* __restrict p, const double* __restrict g,
                           S* __restrict K) {
    physics::edge_stiffness(m.LE[e], S(physics::stiffness_g(g[e], Definite)), &p[3 * std::size_t(e)], &K[9 * std::size_t(e)]);
}

// TSEP terms for the segment of first edge e0 (physics/tsep_stiffness.hpp)
// added to each pair's 4 targets, with (x, y) = (p0, p1), or (p1, p0) when
// transposed, picked by indexing, not by a branch. (A scratch Kp written
// then re-read as vectors stalled on store forwarding.)
template <class S>
EDGEFEM_KERNEL void tsep_stiffness_segment(const EdgeModel<S>& m, index_t e0, const S* __restrict p, S* __restrict K) {
    const S* p0 = &p[3 * std::size_t(e0)];
    for (index_t P = m.tsep_first[e0]; P < m.tsep_first[e0 + 1]; ++P) {
        const S* ends[2] = {p0, &p[3 * std::size_t(m.tsep_other[P])]};
        const S c = physics::pair_coefficient(m.LP[P]);
        for (int k = 0; k < 4; ++k) {
            const index_t t = m.target[P][k];
            physics::add_pair_block(physics::slot_coefficient(c, k), ends[t & 1], ends[(t & 1) ^ 1],
                                    &K[9 * std::size_t(t >> 1)]);
        }
    }
}

// Matrix-free K x worker: d = x(V0) - x(V1); y(V0) -= K(E) d; y(V1) += K(E)^T d.
template <class S>
EDGEFEM_KERNEL void edge_kx(const EdgeModel<S>& m, index_t e, const S* __restrict K, const S* __restrict x,
                    S* __restrict y) {
    const index_t a = m.edge[e][0], b = m.edge[e][1];
    const S* k = &K[9 * std::size_t(e)];
    const S d[3] = {x[3 * a] - x[3 * b], x[3 * a + 1] - x[3 * b + 1], x[3 * a + 2] - x[3 * b + 2]};
    for (int i = 0; i < 3; ++i) {
        y[3 * a + i] -= physics::row_times(k[3 * i], k[3 * i + 1], k[3 * i + 2], d[0], d[1], d[2]);
        y[3 * b + i] += physics::transpose_times(k[i], k[3 + i], k[6 + i], d[0], d[1], d[2]);
    }
}

// K x over the segment of edges whose V0 is `a` (y(a) accumulated in
// registers, as in edge_force_segment). Built-in scalars run it in 4-lane
// vectors: K(E)^T d as three row-times-broadcast FMAs, K(E) d as lane-wise
// products summed once per segment (half the scalar version's operations).
// W is the stride of x and y: 3 (xyz) or 4 (xyz and a pad lane, the
// padded scratch of edge_multiply: one vector load per x(V1) and one
// load + store per y(V1), instead of building and splitting a 3-lane
// vector; the pad lane of y collects garbage and is never read back).
template <int W = 3, class S>
EDGEFEM_KERNEL void edge_kx_segment(const EdgeModel<S>& m, index_t a, const S* __restrict K, const S* __restrict x,
                                    S* __restrict y, const ForwardOut<S>& out) {
    static_assert(W == 3 || W == 4, "x and y hold 3 or 4 values per vertex");
    const auto V1 = second_vertex(m);
    if constexpr (std::is_floating_point_v<S>) {
        using X = Xyz4<S>;
        using V = typename X::V;
        const auto load = [](const S* p) {
            if constexpr (W == 4)
                return X::row(p);
            else
                return X::load(p);
        };
        const V xa = load(&x[W * std::size_t(a)]);
        V r0 = {}, r1 = {}, r2 = {};
        for_segment<W>(m.edge_first[a], m.edge_first[a + 1], V1, out, [&](index_t e, S* yb) {
            const S* k = &K[9 * std::size_t(e)];
            const V d = xa - load(&x[W * std::size_t(V1(e))]);
            const V k0 = X::row(k), k1 = X::row(k + 3), k2 = X::row(k + 6);
            r0 += physics::row_products(k0, d);
            r1 += physics::row_products(k1, d);
            r2 += physics::row_products(k2, d);
            // y(V1) is summed into last: its chain through memory (the next
            // segment often updates the same vertex) stays one add long.
            const V t = physics::transpose_times(k0, k1, k2, d[0], d[1], d[2]);
            if constexpr (W == 4) {
                const V s = X::row(yb) + t;
                __builtin_memcpy(yb, &s, sizeof s);
            } else {
                X::store(yb, X::load(yb) + t);
            }
        });
        S* ya = &y[W * std::size_t(a)];
        ya[0] -= r0[0] + r0[1] + r0[2];
        ya[1] -= r1[0] + r1[1] + r1[2];
        ya[2] -= r2[0] + r2[1] + r2[2];
    } else {
        const S xa0 = x[W * std::size_t(a)], xa1 = x[W * std::size_t(a) + 1], xa2 = x[W * std::size_t(a) + 2];
        S acc0 = 0, acc1 = 0, acc2 = 0;
        for_segment<W>(m.edge_first[a], m.edge_first[a + 1], V1, out, [&](index_t e, S* yb) {
            const index_t b = V1(e);
            const S* k = &K[9 * std::size_t(e)];
            const S d0 = xa0 - x[W * std::size_t(b)], d1 = xa1 - x[W * std::size_t(b) + 1],
                    d2 = xa2 - x[W * std::size_t(b) + 2];
            acc0 += physics::row_times(k[0], k[1], k[2], d0, d1, d2);
            acc1 += physics::row_times(k[3], k[4], k[5], d0, d1, d2);
            acc2 += physics::row_times(k[6], k[7], k[8], d0, d1, d2);
            yb[0] += physics::transpose_times(k[0], k[3], k[6], d0, d1, d2);
            yb[1] += physics::transpose_times(k[1], k[4], k[7], d0, d1, d2);
            yb[2] += physics::transpose_times(k[2], k[5], k[8], d0, d1, d2);
        });
        y[W * std::size_t(a)] -= acc0;
        y[W * std::size_t(a) + 1] -= acc1;
        y[W * std::size_t(a) + 2] -= acc2;
    }
}
template <int W = 3, class S>
EDGEFEM_KERNEL void edge_kx_segment(const EdgeModel<S>& m, index_t a, const S* __restrict K, const S* __restrict x,
                                    S* __restrict y) {
    edge_kx_segment<W>(m, a, K, x, y, direct_only(y));
}

// K x over the segments of vertices [a0, a1), none of them reaching past
// the rows of y: out of line (EDGEFEM_LOOP), so that the restrict pointers
// hold in the loop. Inlined into the owner variant's part lambda (pointers
// reached through its captures) the same loop ran 15 % slower.
template <int W, class S>
EDGEFEM_LOOP void edge_kx_segments(const EdgeModel<S>& m, index_t a0, index_t a1, const S* __restrict K,
                                   const S* __restrict x, S* __restrict y) {
    for (index_t a = a0; a < a1; ++a) edge_kx_segment<W>(m, a, K, x, y);
}

// x (3 per vertex) into the padded x4 (4 per vertex, pad 0) and back, for
// vertices [begin, end).
template <class S>
EDGEFEM_KERNEL void pad_xyz(const S* __restrict x, S* __restrict x4, index_t begin, index_t end) {
    for (index_t v = begin; v < end; ++v) {
        x4[4 * std::size_t(v)] = x[3 * std::size_t(v)];
        x4[4 * std::size_t(v) + 1] = x[3 * std::size_t(v) + 1];
        x4[4 * std::size_t(v) + 2] = x[3 * std::size_t(v) + 2];
        x4[4 * std::size_t(v) + 3] = S(0);
    }
}
template <class S>
EDGEFEM_KERNEL void unpad_xyz(const S* __restrict x4, S* __restrict x, index_t begin, index_t end) {
    for (index_t v = begin; v < end; ++v) {
        x[3 * std::size_t(v)] = x4[4 * std::size_t(v)];
        x[3 * std::size_t(v) + 1] = x4[4 * std::size_t(v) + 1];
        x[3 * std::size_t(v) + 2] = x4[4 * std::size_t(v) + 2];
    }
}

// Diagonal blocks: D(V0) -= K(E), D(V1) -= K(E)^T (translation invariance).
template <class S>
EDGEFEM_KERNEL void edge_diagonal(const EdgeModel<S>& m, index_t e, const S* __restrict K, S* __restrict D) {
    const S* k = &K[9 * std::size_t(e)];
    physics::subtract_block(k, &D[9 * std::size_t(m.edge[e][0])]);
    physics::subtract_block_transposed(k, &D[9 * std::size_t(m.edge[e][1])]);
}

// Diagonal blocks over the segment of edges whose V0 is `a` (D(V1) through
// `out`, as in the segment kernels above): the segment's terms of D(a)
// summed in registers and added once (edge by edge in memory it chained 9
// stores per edge to the same block: edge_diagonal_blocks was 4-5 % of an
// armadillo-7k step). -(a + b) = (-a) - b exactly, so the sum of the
// negated terms is the negated sum of the terms.
template <class S>
EDGEFEM_KERNEL void edge_diagonal_segment(const EdgeModel<S>& m, index_t a, const S* __restrict K, S* __restrict D,
                                  const ForwardOut<S>& out) {
    S acc[9] = {};
    for_segment<9>(m.edge_first[a], m.edge_first[a + 1], second_vertex(m), out,
                   [&](index_t e, S* db) {
                       const S* k = &K[9 * std::size_t(e)];
                       physics::subtract_block(k, acc);
                       physics::subtract_block_transposed(k, db);
                   });
    S* da = &D[9 * std::size_t(a)];
    for (int q = 0; q < 9; ++q) da[q] += acc[q];
}
template <class S>
EDGEFEM_KERNEL void edge_diagonal_segment(const EdgeModel<S>& m, index_t a, const S* __restrict K, S* __restrict D) {
    edge_diagonal_segment(m, a, K, D, direct_only(D));
}

}  // namespace kernel

// ---- Serial reference loops -------------------------------------------------

// Nodal forces f = dW/du (3 #V, overwritten; the internal force 'F(p)' of
// M p'' + D p' + F(p) = h). Returns the energy W when `Energy`, else 0.
// Leaves p~, zeta, g in `st` for edge_stiffness_all.
template <ModelKind Kind, bool Energy, class S>
double edge_forces(const EdgeModel<S>& m, const S* u, S* f, EdgeState<S>& st) {
    const index_t ne = m.num_edges();
    st.resize(ne);
    kernel::edge_strain_range(m, u, 0, ne, st.p.data(), st.zeta.data(), st.g.data());
    std::fill(f, f + 3 * std::size_t(m.num_vertices), S(0));
    if constexpr (Kind == ModelKind::FE)
        for (index_t a = 0; a < m.num_vertices; ++a)
            kernel::tsep_force_segment(m, a, st.p.data(), st.zeta.data(), st.g.data(), f);
    else
        for (index_t a = 0; a < m.num_vertices; ++a) kernel::edge_force_segment(m, a, st.p.data(), st.g.data(), f);
    double W = 0;
    if constexpr (Energy)
        for (index_t e = 0; e < ne; ++e) W += physics::energy_term(double(st.zeta[e]), st.g[e]);
    return physics::energy_from_terms(W);
}

// Per-edge tangent stiffness from the state of the last edge_forces call
// (`Definite`: see kernel::edge_stiffness).
template <ModelKind Kind, bool Definite = false, class S>
void edge_stiffness_all(const EdgeModel<S>& m, const EdgeState<S>& st, EdgeStiffness<S>& K) {
    const index_t ne = m.num_edges();
    if (K.K.size() != 9 * (std::size_t(ne) + 1)) K.resize(ne);
    for (index_t e = 0; e < ne; ++e) kernel::edge_stiffness<Definite>(m, e, st.p.data(), st.g.data(), K.K.data());
    if constexpr (Kind == ModelKind::FE)
        for (index_t e = 0; e < ne; ++e) kernel::tsep_stiffness_segment(m, e, st.p.data(), K.K.data());
}

// y = K x (3 #V, overwritten). Built-in scalars run on padded copies of x
// and y in K's scratch (edge_kx_segment<4>): y(a) is final once segment a
// has run (later segments only write vertices past their own), so it is
// copied out right there. Bitwise the same as on xyz strides; armadillo-7k,
// 1 thread: 3.77 -> 3.45 ns per edge, the copies included (the kernel alone
// on padded vectors: 2.7). The owner variant (parallel/) runs padded copies
// too, in three phases, its loops out of line (edge_kx_segments).
template <class S>
void edge_multiply(const EdgeModel<S>& m, const EdgeStiffness<S>& K, const S* x, S* y) {
    const index_t nv = m.num_vertices;
    if constexpr (std::is_floating_point_v<S>) {
        K.x4.resize(4 * std::size_t(nv));
        K.y4.assign(4 * std::size_t(nv), S(0));
        S* __restrict x4 = K.x4.data();
        S* __restrict y4 = K.y4.data();
        kernel::pad_xyz(x, x4, 0, nv);
        for (index_t a = 0; a < nv; ++a) {
            kernel::edge_kx_segment<4>(m, a, K.K.data(), x4, y4);
            kernel::unpad_xyz(y4, y, a, a + 1);
        }
    } else {
        std::fill(y, y + 3 * std::size_t(nv), S(0));
        for (index_t a = 0; a < nv; ++a) kernel::edge_kx_segment(m, a, K.K.data(), x, y);
    }
}

// The 3x3 diagonal blocks of K (9 #V, row-major, overwritten).
template <class S>
void edge_diagonal_blocks(const EdgeModel<S>& m, const EdgeStiffness<S>& K, S* D) {
    std::fill(D, D + 9 * std::size_t(m.num_vertices), S(0));
    for (index_t a = 0; a < m.num_vertices; ++a) kernel::edge_diagonal_segment(m, a, K.K.data(), D);
}

}  // namespace edgefem
