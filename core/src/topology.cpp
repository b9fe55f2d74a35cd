#include "edgefem/core/topology.hpp"

#include <algorithm>
#include <utility>

#include "group_unique.hpp"

namespace edgefem {

index_t Topology::num_opposite_tseps() const {
    index_t n = 0;
    for (auto o : tsep_opposite) n += o;
    return n;
}

index_t Topology::find_edge(index_t a, index_t b) const {
    if (a > b) std::swap(a, b);
    if (a < 0 || b >= num_vertices || a == b) return -1;
    const auto lo = edges.begin() + first_edge[a];
    const auto hi = edges.begin() + first_edge[a + 1];
    const auto it = std::lower_bound(lo, hi, b, [](const auto& e, index_t v) { return e[1] < v; });
    return (it != hi && (*it)[1] == b) ? static_cast<index_t>(it - edges.begin()) : -1;
}

index_t Topology::find_tsep(index_t e0, index_t e1) const {
    if (e0 > e1) std::swap(e0, e1);
    if (e0 < 0 || e1 >= num_edges() || e0 == e1) return -1;
    const auto lo = tseps.begin() + first_tsep[e0];
    const auto hi = tseps.begin() + first_tsep[e0 + 1];
    const auto it = std::lower_bound(lo, hi, e1, [](const auto& p, index_t v) { return p[1] < v; });
    return (it != hi && (*it)[1] == e1) ? static_cast<index_t>(it - tseps.begin()) : -1;
}

Topology build_topology(const Mesh& mesh) {
    Topology topo;
    topo.num_vertices = mesh.num_vertices();
    topo.num_tets = mesh.num_tets();
    const index_t nt = topo.num_tets;
    const index_t* tets = mesh.tets.data();

    // Edges: bucket by the smaller vertex, value the larger one.
    {
        const auto g = detail::group_unique(topo.num_vertices, std::int64_t{6} * nt, [&](std::int64_t s) {
            const index_t* t = tets + 4 * (s / 6);
            const int k = static_cast<int>(s % 6);
            const index_t a = t[kTetEdge[k][0]], b = t[kTetEdge[k][1]];
            return a < b ? std::pair{a, b} : std::pair{b, a};
        });
        topo.first_edge = g.first;
        topo.edges.resize(g.value.size());
        for (index_t v = 0; v < topo.num_vertices; ++v)
            for (index_t e = g.first[v]; e < g.first[v + 1]; ++e) topo.edges[e] = {v, g.value[e]};
        topo.tet_edges.resize(nt);
        for (index_t t = 0; t < nt; ++t)
            for (int k = 0; k < 6; ++k) topo.tet_edges[t][k] = g.slot_id[6 * std::size_t(t) + k];
    }

    // TSEPs: bucket by the smaller edge, value the larger one. A face's
    // vertex-sharing pairs come from every tet holding the face and merge here.
    {
        const auto g = detail::group_unique(topo.num_edges(), std::int64_t{15} * nt, [&](std::int64_t s) {
            const auto& te = topo.tet_edges[s / 15];
            const int k = static_cast<int>(s % 15);
            const index_t a = te[kTetEdgePair[k][0]], b = te[kTetEdgePair[k][1]];
            return a < b ? std::pair{a, b} : std::pair{b, a};
        });
        const index_t np = static_cast<index_t>(g.value.size());
        topo.tseps.resize(np);
        for (index_t e = 0; e < topo.num_edges(); ++e)
            for (index_t p = g.first[e]; p < g.first[e + 1]; ++p) topo.tseps[p] = {e, g.value[p]};
        topo.tsep_opposite.assign(np, 0);
        for (std::int64_t s = 0; s < std::int64_t{15} * nt; ++s)
            if (s % 15 >= kVertexSharingPairs) topo.tsep_opposite[g.slot_id[s]] = 1;
        topo.first_tsep = g.first;
    }

    // Stiffness targets: the edge joining end i of E0 to end j of E1.
    topo.tsep_targets.resize(topo.tseps.size());
    for (index_t p = 0; p < topo.num_tseps(); ++p) {
        const auto& e0 = topo.edges[topo.tseps[p][0]];
        const auto& e1 = topo.edges[topo.tseps[p][1]];
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) {
                const index_t u = e0[i], w = e1[j];
                Target t = kDiagonalTarget;
                if (u != w) {
                    const index_t e2 = topo.find_edge(u, w);
                    if (e2 < 0) throw Error("internal: TSEP target edge missing (invalid mesh?)");
                    t = (e2 << 1) | (u > w ? 1 : 0);
                }
                topo.tsep_targets[p][2 * i + j] = t;
            }
    }

    detail::build_csr<2>(topo.num_vertices, topo.num_edges(),
                         [&](index_t e) { return topo.edges[e]; }, topo.vertex_edges.offsets,
                         topo.vertex_edges.items);
    detail::build_csr<2>(topo.num_edges(), topo.num_tseps(),
                         [&](index_t p) { return topo.tseps[p]; }, topo.edge_tseps.offsets,
                         topo.edge_tseps.items);
    return topo;
}

}  // namespace edgefem
