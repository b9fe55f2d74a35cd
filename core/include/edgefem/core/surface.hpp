// Surfaces for rendering: the boundary of a tet mesh as outward-wound
// triangles, and a separate (finer) render surface embedded in the tets:
// each of its points moves with the tet it lies in (or, outside the mesh,
// the nearest tet), as the same affine combination of the tet's vertices.
//
//   const BoundarySurface s = boundary_surface(mesh);       // once
//   const Embedding e = embed_points(mesh, render_points);   // once
//   embedded_positions(mesh, e, sim.displacement(), out);    // every frame
//   vertex_normals(render_triangles, out, normals);
#pragma once

#include <array>
#include <span>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

struct BoundarySurface {
    // Faces of exactly one tet, wound so that (b - a) x (c - a) points out of
    // the body; vertex indices are the mesh's.
    std::vector<std::array<index_t, 3>> triangles;
    std::vector<index_t> tet;  // the tet each triangle bounds
    // The mesh vertices the triangles use, ascending.
    std::vector<index_t> vertices() const;
};

// Throws MeshError for a tet naming a vertex outside the mesh or one twice
// (check_mesh_indices).
BoundarySurface boundary_surface(const Mesh& mesh);

// Where each point of a render surface sits in a mesh: its tet and its
// barycentric weights there (summing to 1; negative for a point outside the
// mesh, which then follows its nearest tet affinely).
struct Embedding {
    std::vector<index_t> tet;
    std::vector<std::array<double, 4>> weight;
    // 0 for a point inside its tet; else how far outside (metres, the
    // distance along the most negative weight's gradient, an estimate).
    std::vector<double> outside;
};

// points: 3 P coordinates. Throws InvalidArgument naming the first
// non-finite point or a length that is not a multiple of 3; MeshError for an
// empty mesh or bad indices (check_mesh_indices).
Embedding embed_points(const Mesh& mesh, std::span<const double> points);

// out (3 P) = the embedded points at displacement u (3 #V): sum over the
// tet's vertices of weight (X + u). Throws InvalidArgument for a u or out of
// the wrong length.
template <class S>
void embedded_positions(const Mesh& mesh, const Embedding& e, std::span<const S> u, std::span<double> out);

// Area-weighted unit vertex normals (3 per position) of a triangle mesh
// over `positions` (3 per vertex); 0 for a vertex no triangle uses.
std::vector<double> vertex_normals(std::span<const std::array<index_t, 3>> triangles, std::span<const double> positions);

}  // namespace edgefem
