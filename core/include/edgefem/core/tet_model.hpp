// The conventional per-tet Total Lagrangian StVK method: the reference the
// edge-based kernels are checked against and the baseline they must beat.
#pragma once

#include <array>
#include <type_traits>
#include <vector>

#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"
#include "edgefem/physics/tet_stvk.hpp"

namespace edgefem {

// Per-tet precomputed data: Dm^-1 (row i = grad phi_{i+1}) and the Lamé
// constants premultiplied by the rest volume (every term carries Vol).
template <class S>
struct TetData {
    S Dinv[3][3];
    S vol_lambda;
    S vol_mu;
};

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

template <class S>
struct TetModel {
    index_t num_vertices = 0;
    std::vector<std::array<index_t, 4>> tet;
    std::vector<TetData<S>> data;
    std::vector<double> volume;  // rest volumes (not read by the hot loops)
    // The same tets in batches (built-in scalars only; empty otherwise): what
    // the force and stiffness loops read.
    std::vector<TetBatch<S>> batches;

    index_t num_tets() const { return static_cast<index_t>(tet.size()); }
    index_t num_batches() const { return (num_tets() + kTetBatchLanes - 1) / kTetBatchLanes; }
    // The tet in lane l of batch b (num_tets() or more: a padding lane).
    // Groups of kTetBatchInterleave batches interleave their lanes: lane l of
    // batch j of a group holds the group's tet l * kTetBatchInterleave + j,
    // so the tets of one batch rarely share a vertex and their scatters do
    // not chain through memory (bunny-4k and armadillo-7k, ns per tet: force
    // 12.1-12.3 against 12.2-12.5 with consecutive tets, stiffness 38.7-39.5
    // against 39-42). The last, incomplete group stays in plain order.
    index_t batch_tet(index_t b, int l) const {
        constexpr index_t group = kTetBatchInterleave * kTetBatchLanes;
        if ((b / kTetBatchInterleave + 1) * group > num_tets()) return b * kTetBatchLanes + l;
        return b / kTetBatchInterleave * group + l * kTetBatchInterleave + b % kTetBatchInterleave;
    }
    // Bytes of model data the force loop reads per tet: the batches' (as
    // many as tet + data, padding aside: 104 in double, 60 in float).
    double bytes_per_tet() const {
        if (!batches.empty()) return double(sizeof(batches[0])) * num_batches() / num_tets();
        return sizeof(tet[0]) + sizeof(data[0]);
    }
};

// Per-tet stiffness: the 10 distinct 3x3 blocks K_ab, a <= b, in the order
// (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3) (2,2) (2,3) (3,3), row-major.
template <class S>
struct TetStiffness {
    std::vector<S> K;  // 90 #T
};

using physics::tet_block_index;  // block (a, b), a <= b, in that order

// Throws InvalidArgument on invalid materials.
template <class S>
TetModel<S> make_tet_model(const Mesh& mesh, const Materials& materials);

extern template TetModel<double> make_tet_model<double>(const Mesh&, const Materials&);
extern template TetModel<float> make_tet_model<float>(const Mesh&, const Materials&);

}  // namespace edgefem
