#include "test_meshes.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"

namespace edgefem::test {

std::string shared_mesh_dir() {
    if (const char* env = std::getenv("EDGEFEM_SHARED_MESHES")) return env;
    return EDGEFEM_SHARED_MESHES;
}

std::string shared_mesh_prefix(const std::string& name) {
    const std::string prefix = shared_mesh_dir() + "/" + name;
    if (std::filesystem::exists(prefix + ".node") && std::filesystem::exists(prefix + ".ele"))
        return prefix;
    return {};
}

std::string test_data_dir() { return EDGEFEM_TEST_DATA; }

const std::vector<SharedMeshInfo>& shared_mesh_table() {
    static const std::vector<SharedMeshInfo> table = {
        {"box-1200", 330, 1200, 1749, 11460},
        {"spot-2k", 693, 2452, 3661, 23619},
        {"bunny-4k", 1141, 4066, 6063, 39165},
        {"armadillo-7k", 2186, 7488, 11374, 72495},
        {"bunny-50k", 9819, 50172, 63560, 462258},
        {"armadillo-100k", 19535, 100668, 126950, 926256},
        {"bunny-250k", 44630, 250573, 305145, 2284986},
        {"bunny-1m", 171666, 1003465, 1201713, 9110934},
    };
    return table;
}

std::vector<NamedMesh> test_meshes(long max_tets) {
    std::vector<NamedMesh> out;
    out.push_back({"box1", make_box(1, 1, 1)});
    out.push_back({"box10x5x4", make_box(10, 5, 4)});
    out.push_back({"box3x4x5", make_box(3, 4, 5, 0.02)});
    bool missing = false;
    for (const auto& info : shared_mesh_table()) {
        if (info.tets > max_tets) continue;
        const std::string prefix = shared_mesh_prefix(info.name);
        if (prefix.empty()) {
            missing = true;
            continue;
        }
        out.push_back({info.name, read_tetgen(prefix)});
    }
    if (missing)
        std::fprintf(stderr, "note: shared meshes not found under %s; testing generated boxes only\n",
                     shared_mesh_dir().c_str());
    return out;
}

}  // namespace edgefem::test
