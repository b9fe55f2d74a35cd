// Mesh readers. Every reader returns a Mesh with 0-based indices, fills
// Mesh::source (file, line and file numbering of every vertex and tet) and
// throws MeshError naming file and line on anything malformed: it never
// crashes or hangs on bad input.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

enum class MeshFormat { Auto, TetGen, Gmsh, Medit, Vega };

// What a reader skipped or noticed without failing.
struct ReadReport {
    std::int64_t skipped_elements = 0;  // point, line and surface elements skipped (Gmsh, MEDIT)
    std::string skipped_summary;        // e.g. "2 x triangle, 14 x line"
    std::vector<std::string> warnings;
};

// Every reader keeps the 4 corners of 10-node (quadratic) tets, whose
// mid-edge nodes are left unreferenced, and fails on any other volume element
// (hexahedra, prisms, pyramids, ...): simulating the tets alone would drop
// part of the body. Point, line and surface elements are boundary markup:
// they are skipped and counted in ReadReport.

// TetGen .node/.ele: `path` is the .node file, the .ele file (extensions in
// either case) or their common prefix. 0- or 1-based numbering, '#' comments,
// attributes and boundary markers are accepted; the first tet attribute, if
// any, becomes the region.
Mesh read_tetgen(const std::string& path, ReadReport* report = nullptr);
// Gmsh MSH 2.2 and 4.1 ASCII: tetrahedra (types 4 and 11); the physical tag
// becomes the region.
Mesh read_gmsh(const std::string& path, ReadReport* report = nullptr);
// MEDIT .mesh (ASCII): Vertices, Tetrahedra and TetrahedraP2 sections; the
// tet reference becomes the region; other sections are skipped.
Mesh read_medit(const std::string& path, ReadReport* report = nullptr);
// Vega .veg: *VERTICES and *ELEMENTS (TET) sections, 1-based; material
// sections are skipped and other element types refused.
Mesh read_vega(const std::string& path, ReadReport* report = nullptr);

// Chooses the reader from the extension (.node/.ele or an existing prefix,
// .msh, .mesh, .veg) unless `format` says otherwise.
Mesh read_mesh(const std::string& path, MeshFormat format = MeshFormat::Auto,
               ReadReport* report = nullptr);

}  // namespace edgefem
