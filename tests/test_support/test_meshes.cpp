#include "test_meshes.hpp"

#include <cstdio>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"

namespace edgefem::test {

std::string shared_mesh_dir() { return mesh_dir(EDGEFEM_SHARED_MESHES); }

std::string shared_mesh_prefix(const std::string& name) { return find_named_mesh(shared_mesh_dir(), name); }

std::string test_data_dir() { return EDGEFEM_TEST_DATA; }

std::vector<NamedMesh> test_meshes(long max_tets) {
    std::vector<NamedMesh> out;
    out.push_back({"box1", make_box(1, 1, 1)});
    out.push_back({"box10x5x4", make_box(10, 5, 4)});
    out.push_back({"box3x4x5", make_box(3, 4, 5, 0.02)});
    std::string missing;
    for (const auto& info : shared_mesh_table()) {
        if (info.tets > max_tets) continue;
        const std::string prefix = shared_mesh_prefix(info.name);
        if (prefix.empty()) {
            missing += std::string(missing.empty() ? "" : ", ") + info.name;
            continue;
        }
        out.push_back({info.name, read_tetgen(prefix)});
    }
    if (!missing.empty())
        std::fprintf(stderr, "note: shared meshes not found under %s (%s); testing the others and generated boxes\n",
                     shared_mesh_dir().c_str(), missing.c_str());
    return out;
}

}  // namespace edgefem::test
