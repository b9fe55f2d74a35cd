// Storage layouts of the edge FE force kernel, for measuring what memory
// layout costs (docs/layouts.md, "Layouts"). The computation is exactly
// edge_forces<ModelKind::FE, false> (edge loop -> p~, zeta, g = L(E) zeta;
// TSEP loop g(E0) += L(P) zeta(E1), g(E1) += L(P) zeta(E0); edge scatter
// f(V0) += p~ g, f(V1) -= p~ g), in the same loop structure and summation
// order, with the storage chosen by three template parameters:
//
//   VecLayout   every 3-vector array (u and f per vertex, rest and p~ per
//               edge): AoS (x0 y0 z0 x1 ...) or SoA (x0 x1 ... y0 ... z0 ...,
//               one allocation, three blocks);
//   S           double or float: coefficients (rest, L(E), L(P)) and vectors
//               (u, f, p~, zeta); g stays double as in EdgeState;
//   TsepLayout  TSEP records as split arrays (tsep_other[], LP[]: EdgeModel's
//               form) or packed {int32 E1; S L(P)} records (12 bytes in
//               double, 8 in float: no padding, so split and packed hold the
//               same bytes and differ only in how they stream).
//
// Edges (V0 V1 pairs, segments by V0) and TSEP segments by E0 are held as in
// EdgeModel. Data is built from an EdgeModel<double>; these kernels are for
// comparison only (serial, FE, no energy, no stiffness).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "edgefem/core/edge_model.hpp"
#include "edgefem/physics/edge_force.hpp"
#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/edge_strain.hpp"

namespace edgefem {

enum class VecLayout { AoS, SoA };
enum class TsepLayout { Split, Packed };

// n 3-vectors in one array: component c of item i at index(i, c).
template <VecLayout V, class S>
struct Vec3Array {
    index_t n = 0;
    std::vector<S> data;  // 3 n

    // kItemStride: from one item to the next; component_stride(): from the
    // x of an item to its y and from its y to its z.
    static constexpr std::size_t kItemStride = V == VecLayout::AoS ? 3 : 1;
    std::size_t component_stride() const { return V == VecLayout::AoS ? 1 : std::size_t(n); }
    std::size_t index(index_t i, int c) const { return kItemStride * std::size_t(i) + component_stride() * c; }

    void resize(index_t count) {
        n = count;
        data.assign(3 * std::size_t(count), S(0));
    }
    S& operator()(index_t i, int c) { return data[index(i, c)]; }
    S operator()(index_t i, int c) const { return data[index(i, c)]; }
};

// From / to xyz-interleaved doubles (3 n values).
template <VecLayout V, class S>
Vec3Array<V, S> to_vec3_array(const double* xyz, index_t n) {
    Vec3Array<V, S> a;
    a.resize(n);
    for (index_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) a(i, c) = S(xyz[3 * std::size_t(i) + c]);
    return a;
}

template <VecLayout V, class S>
void from_vec3_array(const Vec3Array<V, S>& a, double* xyz) {
    for (index_t i = 0; i < a.n; ++i)
        for (int c = 0; c < 3; ++c) xyz[3 * std::size_t(i) + c] = double(a(i, c));
}

// A packed TSEP record: no padding (12 bytes in double), read unaligned.
template <class S>
struct __attribute__((packed)) TsepRecord {
    std::int32_t e1;
    S LP;
};
static_assert(sizeof(TsepRecord<double>) == 12 && sizeof(TsepRecord<float>) == 8);

// The TSEP records of a segment list, split or packed; other(P) and LP(P)
// read either the same way.
template <class S, TsepLayout T>
struct TsepRecords;

template <class S>
struct TsepRecords<S, TsepLayout::Split> {
    std::vector<index_t> other;  // #P E1
    std::vector<S> LP;           // #P L(P)
    void assign(const EdgeModel<double>& m) {
        other = m.tsep_other;
        LP.assign(m.LP.begin(), m.LP.end());
    }
    std::size_t bytes() const { return other.size() * sizeof(index_t) + LP.size() * sizeof(S); }
};

template <class S>
struct TsepRecords<S, TsepLayout::Packed> {
    std::vector<TsepRecord<S>> rec;  // #P {E1, L(P)}
    void assign(const EdgeModel<double>& m) {
        rec.resize(m.tsep_other.size());
        for (std::size_t P = 0; P < rec.size(); ++P) rec[P] = {m.tsep_other[P], S(m.LP[P])};
    }
    std::size_t bytes() const { return rec.size() * sizeof(TsepRecord<S>); }
};

template <VecLayout V, class S, TsepLayout T>
struct LayoutModel {
    index_t num_vertices = 0;
    index_t num_tets = 0;
    std::vector<std::array<index_t, 2>> edge;  // #E {V0, V1}, sorted by V0
    std::vector<index_t> edge_first;           // #V + 1
    Vec3Array<V, S> rest;                      // #E rest edge vectors X(V0) - X(V1)
    std::vector<S> LE;                         // #E L(E)
    std::vector<index_t> tsep_first;           // #E + 1
    TsepRecords<S, T> tsep;                    // #P

    index_t num_edges() const { return static_cast<index_t>(edge.size()); }
    // Bytes of precomputed data (everything above) per tet.
    double bytes_per_tet() const {
        const std::size_t b = edge.size() * sizeof(edge[0]) + edge_first.size() * sizeof(index_t) +
                              rest.data.size() * sizeof(S) + LE.size() * sizeof(S) +
                              tsep_first.size() * sizeof(index_t) + tsep.bytes();
        return num_tets > 0 ? double(b) / num_tets : 0.0;
    }
};

template <VecLayout V, class S, TsepLayout T>
LayoutModel<V, S, T> make_layout_model(const EdgeModel<double>& m) {
    LayoutModel<V, S, T> l;
    l.num_vertices = m.num_vertices;
    l.num_tets = m.num_tets;
    l.edge = m.edge;
    l.edge_first = m.edge_first;
    l.rest = to_vec3_array<V, S>(m.rest.data(), m.num_edges());
    l.LE.assign(m.LE.begin(), m.LE.end());
    l.tsep_first = m.tsep_first;
    l.tsep.assign(m);
    return l;
}

// Per-edge state of one evaluation (as EdgeState): p~, zeta, g (double).
template <VecLayout V, class S>
struct LayoutState {
    Vec3Array<V, S> p;
    std::vector<S> zeta;
    std::vector<double> g;
    void resize(index_t num_edges) {
        if (p.n != num_edges) p.resize(num_edges);
        zeta.resize(num_edges);
        g.resize(num_edges);
    }
};

// The three choices as a type, with the name the benchmarks print:
// "<aos|soa>-<double|float>-<split|packed>".
template <VecLayout V, class S, TsepLayout T>
struct LayoutTag {
    static constexpr VecLayout vec = V;
    static constexpr TsepLayout tsep = T;
    using scalar = S;
    using Model = LayoutModel<V, S, T>;
    using Vectors = Vec3Array<V, S>;
    using State = LayoutState<V, S>;
    static std::string name() {
        return std::string(V == VecLayout::AoS ? "aos" : "soa") + (sizeof(S) == 8 ? "-double" : "-float") +
               (T == TsepLayout::Split ? "-split" : "-packed");
    }
};

// Calls f(LayoutTag<...>{}) for each of the 8 combinations, AoS double split
// (EdgeModel's own layout) first.
template <class F>
void for_each_force_layout(F&& f) {
    f(LayoutTag<VecLayout::AoS, double, TsepLayout::Split>{});
    f(LayoutTag<VecLayout::AoS, double, TsepLayout::Packed>{});
    f(LayoutTag<VecLayout::SoA, double, TsepLayout::Split>{});
    f(LayoutTag<VecLayout::SoA, double, TsepLayout::Packed>{});
    f(LayoutTag<VecLayout::AoS, float, TsepLayout::Split>{});
    f(LayoutTag<VecLayout::AoS, float, TsepLayout::Packed>{});
    f(LayoutTag<VecLayout::SoA, float, TsepLayout::Split>{});
    f(LayoutTag<VecLayout::SoA, float, TsepLayout::Packed>{});
}

namespace kernel {

// Component c of item i of a Vec3Array a lives at base + c * cs + s * i,
// s = kItemStride (3 or 1), cs = a.component_stride() (1 or n). The kernels
// take one restrict pointer per component.
// Edge loop: p~(E), zeta(E), g(E) = L(E) zeta(E) (kernel::edge_strain).
template <VecLayout V, class S, TsepLayout T>
inline void layout_edge_strain(const LayoutModel<V, S, T>& m, const Vec3Array<V, S>& uu, LayoutState<V, S>& st) {
    constexpr std::size_t s = Vec3Array<V, S>::kItemStride;
    const std::size_t cu = uu.component_stride(), ce = m.rest.component_stride();
    const S* __restrict ux = uu.data.data();
    const S* __restrict uy = ux + cu;
    const S* __restrict uz = ux + 2 * cu;
    const S* __restrict rx = m.rest.data.data();
    const S* __restrict ry = rx + ce;
    const S* __restrict rz = rx + 2 * ce;
    S* __restrict px = st.p.data.data();
    S* __restrict py = px + ce;
    S* __restrict pz = px + 2 * ce;
    const std::array<index_t, 2>* __restrict edge = m.edge.data();
    const S* __restrict LE = m.LE.data();
    S* __restrict zeta = st.zeta.data();
    double* __restrict g = st.g.data();
    const index_t ne = m.num_edges();
    for (index_t e = 0; e < ne; ++e) {
        const std::size_t a = s * std::size_t(edge[e][0]), b = s * std::size_t(edge[e][1]), i = s * std::size_t(e);
        S q0, q1, q2;
        const S z = physics::edge_strain(ux[a] - ux[b], uy[a] - uy[b], uz[a] - uz[b], rx[i], ry[i], rz[i], q0, q1, q2);
        px[i] = q0;
        py[i] = q1;
        pz[i] = q2;
        zeta[e] = z;
        g[e] = physics::own_g(LE[e], z);
    }
}

// TSEP record P as (E1, L(P)), from split arrays or a packed record.
template <class S>
inline void tsep_record(const TsepRecords<S, TsepLayout::Split>& t, index_t P, index_t& e1, double& L) {
    e1 = t.other.data()[P];
    L = t.LP.data()[P];
}
template <class S>
inline void tsep_record(const TsepRecords<S, TsepLayout::Packed>& t, index_t P, index_t& e1, double& L) {
    // Field by field: copying the whole record goes through the stack, and
    // the 8-byte L(P) load then stalls on store forwarding (5x slower).
    const TsepRecord<S>* r = t.rec.data() + P;
    e1 = r->e1;
    L = r->LP;
}

// TSEP loop over the segments by E0 (kernel::tsep_strain_segment).
template <VecLayout V, class S, TsepLayout T>
inline void layout_tsep_strain(const LayoutModel<V, S, T>& m, LayoutState<V, S>& st) {
    const index_t* __restrict first = m.tsep_first.data();
    const S* __restrict zeta = st.zeta.data();
    double* __restrict g = st.g.data();
    const index_t ne = m.num_edges();
    for (index_t e0 = 0; e0 < ne; ++e0) {
        const double z0 = zeta[e0];
        double acc = 0;
        for (index_t P = first[e0]; P < first[e0 + 1]; ++P) {
            index_t e1;
            double L;
            tsep_record(m.tsep, P, e1, L);
            acc += physics::pair_g(L, double(zeta[e1]));
            g[e1] += physics::pair_g(L, z0);
        }
        g[e0] += acc;
    }
}

// Edge scatter over segments by V0 (kernel::edge_force_segment); f is
// overwritten.
template <VecLayout V, class S, TsepLayout T>
inline void layout_edge_scatter(const LayoutModel<V, S, T>& m, const LayoutState<V, S>& st, Vec3Array<V, S>& ff) {
    constexpr std::size_t s = Vec3Array<V, S>::kItemStride;
    std::fill(ff.data.begin(), ff.data.end(), S(0));
    const std::size_t cv = ff.component_stride(), ce = st.p.component_stride();
    S* __restrict fx = ff.data.data();
    S* __restrict fy = fx + cv;
    S* __restrict fz = fx + 2 * cv;
    const S* __restrict px = st.p.data.data();
    const S* __restrict py = px + ce;
    const S* __restrict pz = px + 2 * ce;
    const std::array<index_t, 2>* __restrict edge = m.edge.data();
    const index_t* __restrict first = m.edge_first.data();
    const double* __restrict g = st.g.data();
    for (index_t a = 0; a < m.num_vertices; ++a) {
        S acc0 = 0, acc1 = 0, acc2 = 0;
        for (index_t e = first[a]; e < first[a + 1]; ++e) {
            const std::size_t b = s * std::size_t(edge[e][1]), i = s * std::size_t(e);
            const S ge = S(g[e]);
            const S v0 = physics::edge_force(px[i], ge), v1 = physics::edge_force(py[i], ge),
                    v2 = physics::edge_force(pz[i], ge);
            acc0 += v0;
            acc1 += v1;
            acc2 += v2;
            fx[b] -= v0;
            fy[b] -= v1;
            fz[b] -= v2;
        }
        const std::size_t ia = s * std::size_t(a);
        fx[ia] += acc0;
        fy[ia] += acc1;
        fz[ia] += acc2;
    }
}

}  // namespace kernel

// Nodal forces f = dW/du of the edge FE model in layout (V, S, T); u and f
// hold #V vectors. Leaves p~, zeta, g in st. Same results as
// edge_forces<ModelKind::FE, false> up to the scalar type.
template <VecLayout V, class S, TsepLayout T>
void layout_forces(const LayoutModel<V, S, T>& m, const Vec3Array<V, S>& u, Vec3Array<V, S>& f,
                   LayoutState<V, S>& st) {
    st.resize(m.num_edges());
    if (f.n != m.num_vertices) f.resize(m.num_vertices);
    kernel::layout_edge_strain(m, u, st);
    kernel::layout_tsep_strain(m, st);
    kernel::layout_edge_scatter(m, st, f);
}

}  // namespace edgefem
