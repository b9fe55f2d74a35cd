#include "sim_common.hpp"

#include <cstdio>
#include <utility>

#include "edgefem/core/output_file.hpp"
#include "output_paths.hpp"

namespace edgefem::cli {

SceneFile load_scene_file(const std::string& path) {
    SceneFile sf = path.empty() ? default_scene_file() : load_scene(path);
    for (const auto& w : sf.warnings) std::fprintf(stderr, "edgefem: warning: %s\n", w.c_str());
    return sf;
}

void write_vertex_map(const std::string& path, const std::vector<index_t>& file_vertex) {
    std::string text = std::string(kVertexMapSignature) +
                       ": line k below is output vertex k-1; it holds that vertex's 0-based index in the mesh file\n";
    for (const index_t v : file_vertex) text += std::to_string(v) + "\n";
    write_file_atomically(path, text);
}

}  // namespace edgefem::cli
