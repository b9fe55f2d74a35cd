// The reference meshes by name (box-1200, bunny-4k, ...): read from a mesh
// folder when present, else replaced by a generated box of about the same
// tet count, so that benchmarks and tests run anywhere.
#pragma once

#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

struct NamedMeshInfo {
    const char* name;
    long vertices, tets, edges, tseps;  // as ../shared/meshes/README.md lists them
};

// The meshes of ../shared/meshes, smallest first.
const std::vector<NamedMeshInfo>& named_mesh_table();

// The folder searched: $EDGEFEM_MESH_DIR if set, else `fallback_dir`.
std::string mesh_dir(const std::string& fallback_dir);

// Path prefix "<dir>/<name>" when <name>.node and <name>.ele exist there, else "".
std::string find_named_mesh(const std::string& dir, const std::string& name);

// Reads <dir>/<name>.node/.ele, or generates a box of the table's tet count
// when absent (the name must then be in the table). `origin` (optional)
// receives the path read or "generated box NXxNYxNZ".
Mesh load_named_mesh(const std::string& dir, const std::string& name, std::string* origin = nullptr);

}  // namespace edgefem
