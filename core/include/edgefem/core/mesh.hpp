// A tetrahedral mesh: rest positions and 4-vertex tets, plus where each item
// came from (so that validation errors can name the file and line).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace edgefem {

// Vertex, edge, TSEP and tet indices. 32 bits halve index traffic in the hot
// loops; meshes up to 2^31-1 items of each kind are supported.
using index_t = std::int32_t;

// Where a mesh's items were read from. Empty vectors mean "unknown" (e.g. a
// generated mesh). Line numbers are 1-based.
struct MeshSource {
    std::string vertex_file;                // file holding the vertices
    std::string tet_file;                   // file holding the tets
    std::vector<std::int64_t> vertex_line;  // vertex_line[v]: line of vertex v
    std::vector<std::int64_t> tet_line;     // tet_line[t]: line of tet t
    std::vector<std::int64_t> vertex_id;    // vertex_id[v]: the vertex number used in the file
    std::vector<std::int64_t> tet_id;       // tet_id[t]: the element number used in the file
    std::string triangle_file;                 // file holding the tagged triangles
    std::vector<std::int64_t> triangle_line;   // triangle_line[k]: line of tagged triangle k
};

// Boundary triangles the mesh file tags, for selections and surface loads
// (docs/scenes.md, "Surface selections"): Gmsh triangles with their physical
// tag (the surface entity's tag when it has none) and $PhysicalNames, the
// TetGen .face file's boundary markers, MEDIT Triangles with their reference.
// Empty for other meshes. The winding is the file's (select_surface orients
// them outward).
struct TaggedTriangles {
    std::vector<index_t> vertices;     // 3 per triangle
    std::vector<int> tag;              // per triangle
    std::map<int, std::string> names;  // tag -> name (Gmsh physical surfaces)

    std::size_t size() const { return tag.size(); }
};

struct Mesh {
    std::vector<double> X;        // 3 * #V rest positions, xyz interleaved (metres)
    std::vector<index_t> tets;    // 4 * #T vertex indices, 0-based
    std::vector<int> region;      // #T region (material) ids, or empty: all region 0
    TaggedTriangles surfaces;     // tagged boundary triangles from the file (or none)
    MeshSource source;

    index_t num_vertices() const { return static_cast<index_t>(X.size() / 3); }
    index_t num_tets() const { return static_cast<index_t>(tets.size() / 4); }
    int tet_region(index_t t) const { return region.empty() ? 0 : region[t]; }

    // "file:line" of tet t / vertex v when known, else "tet t" / "vertex v".
    std::string describe_tet(index_t t) const;
    std::string describe_vertex(index_t v) const;
    std::string describe_triangle(std::size_t k) const;  // tagged triangle k
};

// Signed volume of the tet (a, b, c, d): (b-a).((c-a)x(d-a)) / 6.
double signed_volume(const double* a, const double* b, const double* c, const double* d);

}  // namespace edgefem
