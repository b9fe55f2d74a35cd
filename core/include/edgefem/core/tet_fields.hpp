// Per-tet strain and stress of a displacement, for output: the Green strain
// E, the second Piola-Kirchhoff stress S = lambda tr(E) I + 2 mu E (the StVK
// element's formulas, physics/tet_stvk.hpp) and the von Mises equivalent of
// the Cauchy stress F S F^T / det F (physics/stress_measures.hpp). Each tet is
// homogeneous: one value per tet.
#pragma once

#include <span>

#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"
#include "edgefem/core/tet_model.hpp"

namespace edgefem {

// A symmetric tensor is stored as 6 values per tet in VTK's order
// XX, YY, ZZ, XY, YZ, XZ.
inline constexpr int kSymmetricComponents = 6;

// Spans left empty are not computed. `model`: make_tet_model(mesh,
// materials) (its Dm^-1); the Lame constants are the tet region's. Throws
// InvalidArgument for a u or an output of the wrong length (3 #V; 6 #T,
// 6 #T, #T).
void tet_strain_stress(const Mesh& mesh, const Materials& materials, const TetModel<double>& model,
                       std::span<const double> u, std::span<double> green_strain, std::span<double> pk2_stress,
                       std::span<double> von_mises);

}  // namespace edgefem
