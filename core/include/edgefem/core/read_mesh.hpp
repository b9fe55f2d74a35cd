// Mesh readers. Every reader returns a Mesh with 0-based indices, fills
// Mesh::source (file, line and file numbering of every vertex and tet) and
// throws MeshError naming file and line on anything malformed: it never
// crashes or hangs on bad input.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem {

enum class MeshFormat { Auto, TetGen, Gmsh, Medit, Vega };

// What a reader skipped or noticed without failing.
struct ReadReport {
    std::int64_t skipped_elements = 0;  // point, line and surface elements skipped (Gmsh, MEDIT)
    std::string skipped_summary;        // e.g. "2 x triangle, 14 x line"
    std::vector<std::string> warnings;
    // Materials the file itself assigns to regions (Vega *MATERIAL/*REGION:
    // the i-th *MATERIAL is region i), with their names; empty for the other
    // formats. load_scene uses them (a scene's "regions" override them).
    std::map<int, Material> materials;
    std::map<int, std::string> material_names;
    // The file held higher-order tets (10-, 20-, 35- or 56-node): only their
    // corners are kept, so their other nodes are left unreferenced.
    bool high_order_tets = false;
};

// Every reader keeps the 4 corners of higher-order tets (10-node quadratic
// in every format; in Gmsh also 20-, 35- and 56-node), whose other nodes are
// left unreferenced (ReadReport::high_order_tets; load_scene and the CLI
// then drop them), and fails on any other volume element
// (hexahedra, prisms, pyramids, ...): simulating the tets alone would drop
// part of the body. Point, line and surface elements are boundary markup:
// they are not simulated and are counted in ReadReport; tagged triangles
// are also kept as Mesh::surfaces (Gmsh triangles with their physical tag
// and $PhysicalNames, MEDIT Triangles with their reference, the TetGen
// .face file's boundary markers), for selections and surface loads.

// TetGen .node/.ele: `path` is the .node file, the .ele file (extensions in
// either case) or their common prefix. 0- or 1-based numbering, '#' comments,
// attributes and boundary markers are accepted; the first tet attribute, if
// any, becomes the region. A .face file next to the .node file is read too:
// with boundary markers its faces become the tagged triangles.
Mesh read_tetgen(const std::string& path, ReadReport* report = nullptr);
// Gmsh MSH 2.2 and 4.1 ASCII: tetrahedra (types 4, 11, 29, 30, 31); the
// physical tag becomes the region.
Mesh read_gmsh(const std::string& path, ReadReport* report = nullptr);
// MEDIT .mesh (ASCII): Vertices, Tetrahedra and TetrahedraP2 sections; the
// tet reference becomes the region; other sections are skipped.
Mesh read_medit(const std::string& path, ReadReport* report = nullptr);
// Vega .veg: *VERTICES and *ELEMENTS (TET) sections, 1-based; *MATERIAL
// (ENU: density, Young's modulus, Poisson ratio), *SET and *REGION give
// every tet of a region's set that material: the i-th *MATERIAL becomes
// region i and ReadReport::materials holds its constants (tets in no region
// keep region 0, with a warning). Other material types, other element types
// and *INCLUDE are refused; other sections are skipped with a warning.
Mesh read_vega(const std::string& path, ReadReport* report = nullptr);

// Chooses the reader from the extension (.node/.ele or an existing prefix,
// .msh, .mesh, .veg) unless `format` says otherwise.
Mesh read_mesh(const std::string& path, MeshFormat format = MeshFormat::Auto,
               ReadReport* report = nullptr);

}  // namespace edgefem
