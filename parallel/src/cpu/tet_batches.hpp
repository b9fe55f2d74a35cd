// The per-tet model in the CPU back-end's batches: 4 tets per batch,
// structure-of-arrays, so that the per-tet formulas (physics/tet_stvk.hpp)
// run across the tets in SIMD lanes. A CPU layout: the reference back-end
// and a device back-end read core's TetModel as it is.
#pragma once

#include <array>
#include <type_traits>
#include <vector>

#include "edgefem/core/tet_model.hpp"

namespace edgefem {

// Tets per batch of the lane-batched loops, and the batches per group whose
// lanes are interleaved (see TetModel::batch_tet).
inline constexpr int kTetBatchLanes = 4;
inline constexpr index_t kTetBatchInterleave = 16;

// One lane value per tet of a batch: a 4-lane GCC/Clang vector for built-in
// scalars (a class template: the attribute on a dependent typedef is ignored
// inside function templates); other scalars are never batched.
template <class S, bool = std::is_floating_point_v<S>>
struct TetLanes {
    typedef S V __attribute__((vector_size(kTetBatchLanes * sizeof(S))));
};
template <class S>
struct TetLanes<S, false> {
    using V = std::array<S, kTetBatchLanes>;
};

// TetData and the vertex ids of 4 tets, structure-of-arrays, so that the
// per-tet arithmetic runs across the tets in SIMD lanes. Padding lanes (past
// the last tet) hold zero data and vertex 0: they add exactly zero to
// vertex 0 and read and write nothing out of bounds.
template <class S>
struct TetBatch {
    using V = typename TetLanes<S>::V;
    V Dinv[3][3];
    V vol_lambda;
    V vol_mu;
    index_t v[4][kTetBatchLanes];  // [local vertex][lane]
};


// TetModel plus the same tets in batches (built-in scalars only; empty
// otherwise): what the CPU force and stiffness loops read.
template <class S>
struct BatchedTetModel : TetModel<S> {
    std::vector<TetBatch<S>> batches;

    index_t num_batches() const { return (this->num_tets() + kTetBatchLanes - 1) / kTetBatchLanes; }
    // The tet in lane l of batch b (num_tets() or more: a padding lane).
    // Groups of kTetBatchInterleave batches interleave their lanes: lane l of
    // batch j of a group holds the group's tet l * kTetBatchInterleave + j,
    // so the tets of one batch rarely share a vertex and their scatters do
    // not chain through memory (bunny-4k and armadillo-7k, ns per tet: force
    // 12.1-12.3 against 12.2-12.5 with consecutive tets, stiffness 38.7-39.5
    // against 39-42). The last, incomplete group stays in plain order.
    index_t batch_tet(index_t b, int l) const {
        constexpr index_t group = kTetBatchInterleave * kTetBatchLanes;
        if ((b / kTetBatchInterleave + 1) * group > this->num_tets()) return b * kTetBatchLanes + l;
        return b / kTetBatchInterleave * group + l * kTetBatchInterleave + b % kTetBatchInterleave;
    }
    // Bytes of model data the force loop reads per tet: the batches' (as
    // many as tet + data, padding aside: 104 in double, 60 in float).
    double bytes_per_tet() const {
        if (!batches.empty()) return double(sizeof(batches[0])) * num_batches() / this->num_tets();
        return TetModel<S>::bytes_per_tet();
    }
};

// The model and its batches (no batches for scalars other than float and
// double).
template <class S>
BatchedTetModel<S> make_batched_tet_model(TetModel<S> model) {
    BatchedTetModel<S> m;
    static_cast<TetModel<S>&>(m) = std::move(model);
    if constexpr (std::is_floating_point_v<S>) {
        const index_t nt = m.num_tets();
        m.batches.resize(m.num_batches());
        for (index_t b = 0; b < m.num_batches(); ++b) {
            TetBatch<S>& bt = m.batches[b];
            for (int l = 0; l < kTetBatchLanes; ++l) {
                const index_t t = m.batch_tet(b, l);
                const TetData<S> d = t < nt ? m.data[t] : TetData<S>{};
                for (int i = 0; i < 4; ++i) bt.v[i][l] = t < nt ? m.tet[t][i] : 0;
                for (int i = 0; i < 3; ++i)
                    for (int c = 0; c < 3; ++c) bt.Dinv[i][c][l] = d.Dinv[i][c];
                bt.vol_lambda[l] = d.vol_lambda;
                bt.vol_mu[l] = d.vol_mu;
            }
        }
    }
    return m;
}
template <class S>
BatchedTetModel<S> make_batched_tet_model(const Mesh& mesh, const Materials& materials) {
    return make_batched_tet_model(make_tet_model<S>(mesh, materials));
}

}  // namespace edgefem
