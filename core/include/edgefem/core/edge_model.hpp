// What the edge-based kernels read, in the kernels' scalar type: edge and
// TSEP index pairs with their coefficients, and the stiffness targets.
// Set up once from Topology + Coefficients (MFEM's set-up vs apply split).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/topology.hpp"

namespace edgefem {

// FE: the full StVK tet element. SN: the nonlinear spring network (every
// TSEP term dropped). A template parameter of the kernels, so SN compiles
// the TSEP loops away.
enum class ModelKind { FE, SN };

template <class S>
struct EdgeModel {
    index_t num_vertices = 0;
    index_t num_tets = 0;
    std::vector<std::array<index_t, 2>> edge;  // #E {V0, V1}, sorted by V0
    // Edges with V0 = v are edge_first[v] .. edge_first[v+1]: the scatter
    // loops accumulate f(V0) over such a segment in registers.
    std::vector<index_t> edge_first;           // #V + 1
    std::vector<S> rest;                       // 3 #E rest edge vectors X(V0) - X(V1)
    std::vector<S> LE;                         // #E L(E)
    // TSEPs are held in segments by their first edge E0 (they are sorted by
    // it): the TSEPs with E0 = e are tsep_first[e] .. tsep_first[e+1], and
    // only E1 is stored. A segment accumulates g(E0) in a register instead of
    // chaining stores to the same g(E0), and E0 costs no bytes.
    std::vector<index_t> tsep_first;           // #E + 1
    std::vector<index_t> tsep_other;           // #P E1
    std::vector<S> LP;                         // #P L(P)
    // #P stiffness targets (E2 << 1 | transposed) for slots k = 2i + j; a
    // diagonal target points at the sink block #E, so the stiffness loop has
    // no branch: K holds #E + 1 blocks and the last one is scratch.
    std::vector<std::array<index_t, 4>> target;

    index_t num_edges() const { return static_cast<index_t>(edge.size()); }
    index_t num_tseps() const { return static_cast<index_t>(tsep_other.size()); }
    // Bytes of precomputed model data (everything above) per tet, with and
    // without the stiffness targets (force-only use needs no targets).
    double bytes_per_tet(bool with_stiffness = true) const;
};

template <class S>
EdgeModel<S> make_edge_model(const Topology& topo, const Coefficients& coef);

// The same model in another scalar type: indices copied, coefficients
// converted (e.g. to an instrumented scalar that counts operations).
template <class To, class From>
EdgeModel<To> convert_scalar(const EdgeModel<From>& m) {
    EdgeModel<To> c;
    c.num_vertices = m.num_vertices;
    c.num_tets = m.num_tets;
    c.edge = m.edge;
    c.edge_first = m.edge_first;
    c.rest.assign(m.rest.begin(), m.rest.end());
    c.LE.assign(m.LE.begin(), m.LE.end());
    c.tsep_first = m.tsep_first;
    c.tsep_other = m.tsep_other;
    c.LP.assign(m.LP.begin(), m.LP.end());
    c.target = m.target;
    return c;
}

extern template struct EdgeModel<double>;
extern template struct EdgeModel<float>;
extern template EdgeModel<double> make_edge_model<double>(const Topology&, const Coefficients&);
extern template EdgeModel<float> make_edge_model<float>(const Topology&, const Coefficients&);

}  // namespace edgefem
