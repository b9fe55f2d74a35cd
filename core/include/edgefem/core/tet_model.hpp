// The conventional per-tet Total Lagrangian StVK method: the reference the
// edge-based kernels are checked against and the baseline they must beat.
#pragma once

#include <array>
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

template <class S>
struct TetModel {
    index_t num_vertices = 0;
    std::vector<std::array<index_t, 4>> tet;
    std::vector<TetData<S>> data;
    std::vector<double> volume;  // rest volumes (not read by the hot loops)
    index_t num_tets() const { return static_cast<index_t>(tet.size()); }
    // Bytes of model data per tet (vertex ids, Dm^-1, Vol lambda, Vol mu).
    double bytes_per_tet() const { return sizeof(tet[0]) + sizeof(data[0]); }
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
