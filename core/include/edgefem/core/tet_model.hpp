// The conventional per-tet Total Lagrangian StVK method: the reference the
// edge-based kernels are checked against and the baseline they must beat.
#pragma once

#include <array>
#include <vector>

#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"

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
    double bytes_per_tet() const { return sizeof(tet[0]) + sizeof(data[0]); }
};

// Throws InvalidArgument on invalid materials.
template <class S>
TetModel<S> make_tet_model(const Mesh& mesh, const Materials& materials);

extern template TetModel<double> make_tet_model<double>(const Mesh&, const Materials&);
extern template TetModel<float> make_tet_model<float>(const Mesh&, const Materials&);

}  // namespace edgefem
