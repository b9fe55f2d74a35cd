// Surface selections: the triangles a scene names by the mesh file's tag
// (Gmsh physical surface, TetGen boundary marker, MEDIT reference), by a
// Gmsh physical name, by a box, or the whole boundary; and the vertices they
// hold. Selections for loads are wound outward (docs/scenes.md, "Surface
// selections").
#pragma once

#include <array>
#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

using Triangle = std::array<index_t, 3>;

// The tagged triangles (Mesh::surfaces) whose tag is one of `tags`, in the
// file's winding. InvalidArgument naming the first tag no triangle has (and
// the tags the mesh has).
std::vector<Triangle> tagged_triangles(const Mesh& mesh, const std::vector<int>& tags);

// The tags a Gmsh physical name names (TaggedTriangles::names);
// InvalidArgument naming it (and the names the mesh has) when none.
std::vector<int> tags_named(const Mesh& mesh, const std::string& name);

// The same triangles wound outward: each must be a face of exactly one tet
// (a boundary face); MeshError naming the first that is not (an interior
// face has no outside: a load there is an error).
std::vector<Triangle> orient_outward(const Mesh& mesh, const std::vector<Triangle>& triangles);

// The boundary faces (outward) whose three vertices lie in [lo, hi].
std::vector<Triangle> boundary_in_box(const Mesh& mesh, const std::array<double, 3>& lo,
                                      const std::array<double, 3>& hi);

// The vertices the triangles use, ascending.
std::vector<index_t> triangle_vertices(const std::vector<Triangle>& triangles);

}  // namespace edgefem
