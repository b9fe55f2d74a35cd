// The rest-shape data of the edge-based formulation, in double precision:
// H(E), L(E), L(P) (formulation.md, "Energy as a bi-quadratic form") and the
// rest edge vectors from which zeta is computed without cancellation.
#pragma once

#include <vector>

#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"
#include "edgefem/core/topology.hpp"

namespace edgefem {

struct Coefficients {
    std::vector<double> rest_edge;   // 3 * #E: X(V0) - X(V1)
    std::vector<double> H;           // #E: squared rest length |X(V0) - X(V1)|^2
    std::vector<double> LE;          // #E: L(E)
    std::vector<double> LP;          // #P: L(P)
    std::vector<double> tet_volume;  // #T: rest volume
};

// Per-tet barycentric gradients a_0..a_3 (3 x 4, column i = grad phi_i) and
// volume of the rest tet; the gradients sum to zero.
struct TetGradients {
    double a[4][3];
    double volume;
};
TetGradients tet_gradients(const Mesh& mesh, index_t t);

// A_ef(T) for the 6 local edges of tet T (kTetEdge order), symmetric 6 x 6.
void tet_edge_form(const TetGradients& g, double lambda, double mu, double A[6][6]);

// Throws InvalidArgument if a material is invalid.
Coefficients compute_coefficients(const Mesh& mesh, const Topology& topo, const Materials& materials);

// Lumped mass rho Vol / 4 per tet vertex, summed per vertex (#V).
std::vector<double> lumped_mass(const Mesh& mesh, const Materials& materials);

}  // namespace edgefem
