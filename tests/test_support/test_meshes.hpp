// Meshes the tests run on: generated boxes always, and the meshes in
// ../shared/meshes when that folder is present (a message says when not).
#pragma once

#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"
#include "lab/named_mesh.hpp"

namespace edgefem::test {

struct NamedMesh {
    std::string name;
    Mesh mesh;
};

// Folder of the shared meshes ($EDGEFEM_MESH_DIR overrides).
std::string shared_mesh_dir();
// Path prefix of a shared TetGen mesh ("<dir>/bunny-4k"), or "" if absent.
std::string shared_mesh_prefix(const std::string& name);
// Folder with the small test files kept in tests/data.
std::string test_data_dir();

inline const std::vector<NamedMeshInfo>& shared_mesh_table() { return named_mesh_table(); }

// Generated boxes (1x1x1, the paper's 10x5x4, a 3x4x5 box) plus every shared
// mesh with at most `max_tets` tets that is present.
std::vector<NamedMesh> test_meshes(long max_tets = 250000);

}  // namespace edgefem::test
