// One VTK XML UnstructuredGrid piece, written ASCII (numbers in shortest
// round-trip form) or binary: every array zlib-compressed into the appended
// raw data, in vtkZLibDataCompressor's block layout with UInt64 headers
// (docs/scenes.md, "Output of edgefem simulate"). What write_vtu (tets) and
// write_surface_vtu (triangles) share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "edgefem/core/write_vtu.hpp"

namespace edgefem::detail {

// A piece of `connectivity.size() / size` cells of `size` points and VTK
// cell type `type` over `positions` (3 per point), with `region` (one per
// cell) and the given fields (VtuFields: point arrays per point, cell arrays
// per cell). Written through an OutputFile (whole or not at all); IoError
// naming the file on failure.
void write_cells(const std::string& path, std::span<const double> positions, std::span<const index_t> connectivity,
                 int size, std::uint8_t type, std::span<const int> region, const VtuFields& fields, VtuFormat format);

// Shortest round-trip text of x (std::to_chars).
std::string shortest(double x);

}  // namespace edgefem::detail
