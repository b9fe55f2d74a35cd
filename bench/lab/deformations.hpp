// Deterministic test configurations of a mesh, as displacements u = x - X
// (3 #V). The CLI's --deform, the tests and the benchmarks use these.
#pragma once

#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

enum class Deformation { Twist, Rotate, Random, Affine };

// Parses "twist", "rotate", "random", "affine"; throws InvalidArgument otherwise.
Deformation parse_deformation(const std::string& name);

// With c the bounding-box centre and `extent` its longest side:
//  twist:  (x, y) rotated about the z axis through c by theta = 1.5 (z - c_z) / extent,
//          z' = c_z + 1.3 (z - c_z)
//  rotate: rigid rotation by 0.7 rad about (1, 2, 3) / sqrt(14) through c
//  random: rest + uniform noise in [-0.05, 0.05] extent per coordinate (seed 12345)
//  affine: x = c + A (X - c), A = [[1.1, 0.2, -0.1], [0.05, 0.9, 0.15], [-0.2, 0.1, 1.2]]
// `scale` multiplies the displacement (1 = the configuration above).
std::vector<double> deformation_displacement(const Mesh& mesh, Deformation kind, double scale = 1.0);

// Positions X + u (3 #V).
std::vector<double> positions_from_displacement(const Mesh& mesh, const std::vector<double>& u);

}  // namespace edgefem
