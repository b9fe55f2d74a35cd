#include "sim_common.hpp"

#include <cstdio>
#include <utility>

#include "cpu/tet_kernels.hpp"
#include "edgefem/core/output_file.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "output_paths.hpp"

namespace edgefem::cli {

SceneFile load_scene_file(const std::string& path) {
    SceneFile sf = path.empty() ? default_scene_file() : load_scene(path);
    for (const auto& w : sf.warnings) std::fprintf(stderr, "edgefem: warning: %s\n", w.c_str());
    return sf;
}

FrameWriter::FrameWriter(const Scene& scene, std::vector<index_t> file_vertex)
    : mesh_(scene.mesh), file_vertex_(std::move(file_vertex)) {
    if (scene.model == ModelKind::FE) {
        tets_ = make_tet_model<double>(scene.mesh, scene.materials);
        density_.resize(tets_->num_tets());
    }
}

void FrameWriter::write(const std::string& path, std::span<const double> u, std::span<const double> f) {
    VtuFields fields;
    fields.displacement = u.data();
    fields.force = f.data();
    if (tets_) {
        tet_energies(*tets_, u.data(), density_.data());
        for (std::size_t t = 0; t < density_.size(); ++t) density_[t] /= tets_->volume[t];
        fields.energy_density = density_.data();
    }
    if (!file_vertex_.empty()) fields.file_vertex = file_vertex_.data();
    write_vtu(path, mesh_, fields);
}

void write_vertex_map(const std::string& path, const std::vector<index_t>& file_vertex) {
    std::string text = std::string(kVertexMapSignature) +
                       ": line k below is output vertex k-1; it holds that vertex's 0-based index in the mesh file\n";
    for (const index_t v : file_vertex) text += std::to_string(v) + "\n";
    write_file_atomically(path, text);
}

}  // namespace edgefem::cli
