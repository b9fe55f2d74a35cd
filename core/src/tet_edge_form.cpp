#include "edgefem/core/tet_edge_form.hpp"

#include <algorithm>
#include <array>
#include <numeric>

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
    return f;
}

template struct TetEdgeForm<double>;
template struct TetEdgeForm<float>;
template TetEdgeForm<double> make_tet_edge_form<double>(const Mesh&, const Topology&, const Materials&);
template TetEdgeForm<float> make_tet_edge_form<float>(const Mesh&, const Topology&, const Materials&);

}  // namespace edgefem
