// A triangle surface (e.g. boundary_surface's, its vertices renumbered
// 0..P-1) for renderers and engines: PLY (binary little endian: float32
// positions and normals, int32 indices) or Wavefront OBJ (text, shortest
// round-trip doubles, 1-based indices). Triangles keep their winding
// (outward for boundary_surface). Or as VTU: VTK_TRIANGLE cells with
// fields. Written whole or not at all (OutputFile).
#pragma once

#include <array>
#include <span>
#include <string>

#include "edgefem/core/mesh.hpp"
#include "edgefem/core/write_vtu.hpp"

namespace edgefem {

// positions: 3 P; normals: 3 P, or empty to leave them out. Throws
// InvalidArgument for a length that is not 3 P or a triangle naming a point
// outside 0..P-1, IoError naming the file when it cannot be written.
void write_ply(const std::string& path, std::span<const double> positions,
               std::span<const std::array<index_t, 3>> triangles, std::span<const double> normals = {});
void write_obj(const std::string& path, std::span<const double> positions,
               std::span<const std::array<index_t, 3>> triangles, std::span<const double> normals = {});

// An UnstructuredGrid of VTK_TRIANGLE cells: points `positions`, `region`
// (one per triangle, e.g. its tet's) as cell data; the fields' point arrays
// have P entries (normals among them), the cell arrays one per triangle.
// Throws as write_ply, and for a region of the wrong length.
void write_surface_vtu(const std::string& path, std::span<const double> positions,
                       std::span<const std::array<index_t, 3>> triangles, std::span<const int> region,
                       const VtuFields& fields = {}, VtuFormat format = VtuFormat::Binary);

}  // namespace edgefem
