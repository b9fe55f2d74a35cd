#include "lab/named_mesh.hpp"

#include <cstdlib>
#include <filesystem>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"

namespace edgefem {

const std::vector<NamedMeshInfo>& named_mesh_table() {
    static const std::vector<NamedMeshInfo> table = {
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

std::string mesh_dir(const std::string& fallback_dir) {
    if (const char* env = std::getenv("EDGEFEM_MESH_DIR"); env && *env) return env;
    return fallback_dir;
}

std::string find_named_mesh(const std::string& dir, const std::string& name) {
    const std::string prefix = dir + "/" + name;
    std::error_code ec;
    if (std::filesystem::exists(prefix + ".node", ec) && std::filesystem::exists(prefix + ".ele", ec))
        return prefix;
    return {};
}

Mesh load_named_mesh(const std::string& dir, const std::string& name, std::string* origin) {
    if (const std::string prefix = find_named_mesh(dir, name); !prefix.empty()) {
        if (origin) *origin = prefix;
        return read_tetgen(prefix);
    }
    for (const auto& info : named_mesh_table())
        if (name == info.name) {
            if (name == "box-1200") {  // the generated box is the exact mesh
                if (origin) *origin = "generated box 10x5x4";
                return make_box(10, 5, 4);
            }
            Mesh mesh = make_box_of_size(static_cast<double>(info.tets));
            if (origin) *origin = "generated box of " + std::to_string(mesh.num_tets()) + " tets";
            return mesh;
        }
    throw InvalidArgument("unknown mesh name '" + name + "' and no " + name + ".node/.ele under " + dir);
}

}  // namespace edgefem
