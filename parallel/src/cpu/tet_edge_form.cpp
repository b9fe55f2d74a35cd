#include "cpu/tet_edge_form.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

template <class S>
TetEdgeForm<S> make_tet_edge_form(const Mesh& mesh, const Topology& topo, const Materials& materials) {
    materials.validate();
    constexpr int L = kTetLanes<S>;
    TetEdgeForm<S> f;
    f.num_tets = topo.num_tets;
    f.num_edges = topo.num_edges();
    const std::size_t nb = f.num_batches();
    f.edge.assign(nb * 6 * L, 0);
    f.A.assign(nb * kFormRows * L, S(0));
    // Tets in the order of their sorted vertex tuples: consecutive tets share
    // their lowest vertex, so the K(E) blocks they update (edges are sorted
    // by V0) and the p~ they read are neighbours in memory.
    std::vector<std::array<index_t, 4>> sorted(topo.num_tets);
    for (index_t t = 0; t < topo.num_tets; ++t) {
        const index_t* v = &mesh.tets[4 * std::size_t(t)];
        sorted[t] = {v[0], v[1], v[2], v[3]};
        std::sort(sorted[t].begin(), sorted[t].end());
    }
    f.slot_tet.resize(topo.num_tets);
    std::iota(f.slot_tet.begin(), f.slot_tet.end(), index_t(0));
    std::sort(f.slot_tet.begin(), f.slot_tet.end(), [&](index_t x, index_t y) { return sorted[x] < sorted[y]; });
    // Lanes interleaved in groups of kInterleave batches: lane l of batch j
    // of a group holds the group's sorted tet l * kInterleave + j. Sorted
    // neighbours share edges, so in one batch they chained the g(E) and K(E)
    // read-modify-writes through memory; kInterleave apart they rarely do,
    // and a group still covers consecutive sorted tets (each batch's lane 0
    // is its smallest, which the owner variant's parts rely on).
    // bench: g pass 7.7 -> 5.7 ns/tet on bunny-4k and armadillo-7k
    // (groups of 4: 6.3, 8: 5.8), bunny-1m 15.5 -> 14.6; the stiffness
    // 46 -> 43. The last, incomplete group stays in plain order.
    constexpr index_t kInterleave = 16;
    const index_t group_tets = kInterleave * L;
    const index_t full = topo.num_tets / group_tets * group_tets;
    std::vector<index_t> sorted_tet = std::move(f.slot_tet);
    f.slot_tet.assign(topo.num_tets, 0);
    for (index_t s = 0; s < topo.num_tets; ++s) {
        index_t slot = s;
        if (s < full) {
            const index_t g = s / group_tets, w = s % group_tets;
            slot = (g * kInterleave + w % kInterleave) * L + w / kInterleave;
        }
        f.slot_tet[slot] = sorted_tet[s];
    }
    for (index_t slot = 0; slot < topo.num_tets; ++slot) {
        const index_t t = f.slot_tet[slot];
        const index_t b = slot / L, lane = slot % L;
        const index_t* v = &mesh.tets[4 * std::size_t(t)];
        // perm[i]: the original local index of the i-th smallest vertex.
        int perm[4] = {0, 1, 2, 3};
        std::sort(perm, perm + 4, [&](int x, int y) { return v[x] < v[y]; });
        const TetGradients g0 = tet_gradients(mesh, t);
        TetGradients g = g0;
        for (int i = 0; i < 4; ++i)
            for (int r = 0; r < 3; ++r) g.a[i][r] = g0.a[perm[i]][r];
        double A[6][6];
        const Material& mat = materials.of(mesh.tet_region(t));
        tet_edge_form(g, mat.lambda(), mat.mu(), A);
        const auto& te = topo.tet_edges[t];
        for (int k = 0; k < 6; ++k) {
            const index_t a = v[perm[kTetEdge[k][0]]], c = v[perm[kTetEdge[k][1]]];
            index_t id = -1;
            for (int q = 0; q < 6; ++q)
                if (topo.edges[te[q]][0] == a && topo.edges[te[q]][1] == c) id = te[q];
            if (id < 0) throw Error("internal: edge of " + mesh.describe_tet(t) + " missing");
            f.edge[(b * 6 + k) * L + lane] = id;
            for (int m = k + 1; m < 6; ++m) f.A[(b * kFormRows + kSym[k][m]) * L + lane] = S(A[k][m]);
        }
    }
    // Padding lanes of the last batch (A = 0) repeat lane 0's edges: the
    // kernels load every lane's zeta or p~, and an edge the batch reads
    // anyway is one the parallel variants order before it (edge 0 was
    // another thread's, read while it wrote: a data race, ThreadSanitizer
    // on the owner variant, 2026-11-27).
    if (const index_t real = f.num_tets % L; real != 0)
        for (int k = 0; k < 6; ++k)
            for (index_t lane = real; lane < L; ++lane)
                f.edge[((nb - 1) * 6 + k) * L + lane] = f.edge[((nb - 1) * 6 + k) * L];
    f.tiles = plan_form_tiles(f, topo.edges, topo.first_edge, kFormTileBatches);
    // Without locality (a shuffled numbering: the first tile already needs
    // half the edges' strains) tiles save nothing: bunny-1m shuffled ran
    // 55-69 ns/tet in one tile, 64 in tiles (3 runs each). One tile then.
    if (f.tiles.size() > 1 && f.tiles.front().edge_end > f.num_edges / 2) f.tiles.clear();
    return f;
}

template <class S>
std::vector<FormTile> plan_form_tiles(const TetEdgeForm<S>& form, const std::vector<std::array<index_t, 2>>& edges,
                                      const std::vector<index_t>& first_edge, index_t batches_per_tile) {
    if (batches_per_tile < 1) throw InvalidArgument("plan_form_tiles: batches_per_tile must be >= 1");
    if (first_edge.empty() || first_edge.front() != 0 || first_edge.back() != index_t(edges.size()))
        throw InvalidArgument("plan_form_tiles: first_edge does not match the edge list");
    const index_t nb = form.num_batches(), nv = index_t(first_edge.size()) - 1, ne = index_t(edges.size());
    for (index_t v = 0; v < nv; ++v) {
        if (first_edge[v + 1] < first_edge[v])
            throw InvalidArgument("plan_form_tiles: first_edge decreases at vertex " + std::to_string(v));
        for (index_t e = first_edge[v]; e < first_edge[v + 1]; ++e)
            if (e < 0 || e >= ne || edges[e][0] != v || edges[e][1] <= v || edges[e][1] >= nv)
                throw InvalidArgument("plan_form_tiles: edge " + std::to_string(e) +
                                      " is not listed under its V0 or its V1 is out of range");
    }
    return plan_form_tiles(form, edges, first_edge, batches_per_tile, FormTileRange{0, nb, 0, ne, 0, nv});
}

template <class S>
std::vector<FormTile> plan_form_tiles(const TetEdgeForm<S>& form, const std::vector<std::array<index_t, 2>>& edges,
                                      const std::vector<index_t>& first_edge, index_t batches_per_tile,
                                      const FormTileRange& r) {
    if (batches_per_tile < 1) throw InvalidArgument("plan_form_tiles: batches_per_tile must be >= 1");
    const index_t nv = index_t(first_edge.size()) - 1, ne = index_t(edges.size());
    if (!(0 <= r.batch_begin && r.batch_begin <= r.batch_end && r.batch_end <= form.num_batches() &&
          0 <= r.edge_begin && r.edge_begin <= r.edge_end && r.edge_end <= ne && 0 <= r.vertex_begin &&
          r.vertex_begin <= r.vertex_end && r.vertex_end <= nv))
        throw InvalidArgument("plan_form_tiles: the range lies outside the form, the edges or the vertices");
    constexpr int L = kTetLanes<S>;
    const index_t nb = r.batch_end - r.batch_begin;
    // Per batch: the lowest V0 of its edges (its tets' lowest vertex) and
    // its largest edge id; real lanes only (padding lanes are never written).
    std::vector<index_t> low(nb), high(nb);
    for (index_t i = 0; i < nb; ++i) {
        const index_t b = r.batch_begin + i;
        index_t lo = r.vertex_end, hi = 0;
        for (int k = 0; k < 6; ++k)
            for (int l = 0; l < form.batch_size(b); ++l) {
                const index_t e = form.edge[(std::size_t(b) * 6 + k) * L + l];
                if (e < 0 || e >= ne) throw InvalidArgument("plan_form_tiles: the form indexes an edge out of range");
                lo = std::min(lo, edges[e][0]);
                hi = std::max(hi, e + 1);
            }
        low[i] = lo;
        high[i] = hi;
    }
    std::vector<index_t> low_after(std::size_t(nb) + 1, r.vertex_end);  // lowest V0 of the batches from i on
    for (index_t i = nb; i-- > 0;) low_after[i] = std::min(low_after[i + 1], low[i]);
    std::vector<FormTile> tiles;
    index_t edge_end = r.edge_begin, zero_end = r.vertex_begin, vertex_end = r.vertex_begin;
    index_t scanned = first_edge[r.vertex_begin];
    for (index_t i0 = 0;; i0 += batches_per_tile) {
        const index_t i1 = std::min(nb, i0 + batches_per_tile);
        const bool last = i1 == nb;
        for (index_t i = i0; i < i1; ++i) edge_end = std::max(edge_end, std::min(high[i], r.edge_end));
        // Segments below the next tiles' lowest vertex have all their batches.
        vertex_end = std::max(vertex_end, last ? r.vertex_end : std::min(low_after[i1], r.vertex_end));
        edge_end = std::max(edge_end, first_edge[vertex_end]);  // the scatter reads their p~
        // The scatter writes f(V1) of those segments' edges: zeroed first.
        for (; scanned < first_edge[vertex_end]; ++scanned) zero_end = std::max(zero_end, edges[scanned][1] + 1);
        zero_end = std::max(zero_end, vertex_end);
        tiles.push_back({r.batch_begin + i1, last ? r.edge_end : edge_end, vertex_end, last ? r.vertex_end : zero_end});
        if (last) break;
    }
    return tiles;
}

template struct TetEdgeForm<double>;
template struct TetEdgeForm<float>;
template TetEdgeForm<double> make_tet_edge_form<double>(const Mesh&, const Topology&, const Materials&);
template TetEdgeForm<float> make_tet_edge_form<float>(const Mesh&, const Topology&, const Materials&);
template std::vector<FormTile> plan_form_tiles<double>(const TetEdgeForm<double>&,
                                                       const std::vector<std::array<index_t, 2>>&,
                                                       const std::vector<index_t>&, index_t);
template std::vector<FormTile> plan_form_tiles<float>(const TetEdgeForm<float>&,
                                                      const std::vector<std::array<index_t, 2>>&,
                                                      const std::vector<index_t>&, index_t);
template std::vector<FormTile> plan_form_tiles<double>(const TetEdgeForm<double>&,
                                                       const std::vector<std::array<index_t, 2>>&,
                                                       const std::vector<index_t>&, index_t, const FormTileRange&);
template std::vector<FormTile> plan_form_tiles<float>(const TetEdgeForm<float>&,
                                                      const std::vector<std::array<index_t, 2>>&,
                                                      const std::vector<index_t>&, index_t, const FormTileRange&);

}  // namespace edgefem
