#include "frame_writer.hpp"

#include <utility>

#include "cpu/tet_kernels.hpp"
#include "edgefem/core/tet_fields.hpp"
#include "edgefem/core/write_surface.hpp"
#include "edgefem/core/write_vtu.hpp"

namespace edgefem::cli {

namespace {

VtuFormat vtu_format(OutputFormat f) { return f == OutputFormat::Ascii ? VtuFormat::Ascii : VtuFormat::Binary; }

// values[item[k] * n .. + n] for each k: per-vertex or per-tet arrays to the
// surface's points or triangles.
std::vector<double> gather(std::span<const double> values, const std::vector<index_t>& item, std::size_t n) {
    std::vector<double> out(item.size() * n);
    for (std::size_t k = 0; k < item.size(); ++k)
        for (std::size_t c = 0; c < n; ++c) out[n * k + c] = values[n * std::size_t(item[k]) + c];
    return out;
}

}  // namespace

FrameWriter::FrameWriter(const Scene& scene, const OutputSettings& output, std::vector<index_t> file_vertex)
    : scene_(scene), output_(output), file_vertex_(std::move(file_vertex)) {
    const std::size_t nt = std::size_t(scene.mesh.num_tets());
    const OutputFields& want = output_.fields;
    if (scene.model == ModelKind::FE) {
        tets_ = make_tet_model<double>(scene.mesh, scene.materials);
        if (want.energy_density) energy_density_.resize(nt);
        if (want.green_strain) green_strain_.resize(kSymmetricComponents * nt);
        if (want.pk2_stress) pk2_stress_.resize(kSymmetricComponents * nt);
        if (want.von_mises) von_mises_.resize(nt);
    }
    if (output_.mesh == OutputMesh::Surface) {
        const BoundarySurface b = boundary_surface(scene.mesh);
        surface_vertex_ = b.vertices();
        std::vector<index_t> local(std::size_t(scene.mesh.num_vertices()), -1);
        for (std::size_t k = 0; k < surface_vertex_.size(); ++k) local[std::size_t(surface_vertex_[k])] = index_t(k);
        triangles_.reserve(b.triangles.size());
        for (const auto& t : b.triangles) triangles_.push_back({local[t[0]], local[t[1]], local[t[2]]});
        triangle_tet_ = b.tet;
        for (const index_t t : triangle_tet_) triangle_region_.push_back(scene.mesh.tet_region(t));
        surface_file_vertex_ = surface_vertex_;
        if (!file_vertex_.empty())
            for (index_t& v : surface_file_vertex_) v = file_vertex_[std::size_t(v)];
    }
}

void FrameWriter::compute_cell_fields(std::span<const double> u) {
    if (!tets_) return;
    if (!energy_density_.empty()) {
        tet_energies(*tets_, u.data(), energy_density_.data());
        for (std::size_t t = 0; t < energy_density_.size(); ++t) energy_density_[t] /= tets_->volume[t];
    }
    if (!green_strain_.empty() || !pk2_stress_.empty() || !von_mises_.empty())
        tet_strain_stress(scene_.mesh, scene_.materials, *tets_, u, green_strain_, pk2_stress_, von_mises_);
}

void FrameWriter::write(const std::string& path, std::span<const double> u, std::span<const double> v,
                        std::span<const double> f) {
    if (output_.mesh == OutputMesh::Surface) return write_surface(path, u, v, f);
    compute_cell_fields(u);
    const OutputFields& want = output_.fields;
    const auto ptr = [](const std::vector<double>& x) { return x.empty() ? nullptr : x.data(); };
    VtuFields fields;
    fields.displacement = want.displacement ? u.data() : nullptr;
    fields.velocity = want.velocity && !v.empty() ? v.data() : nullptr;
    fields.force = want.force ? f.data() : nullptr;
    fields.energy_density = ptr(energy_density_);
    fields.green_strain = ptr(green_strain_);
    fields.pk2_stress = ptr(pk2_stress_);
    fields.von_mises = ptr(von_mises_);
    if (!file_vertex_.empty()) fields.file_vertex = file_vertex_.data();
    if (want.displacement) return write_vtu(path, scene_.mesh, fields, vtu_format(output_.format));
    // The points move without the displacement field too.
    Mesh deformed = scene_.mesh;
    for (std::size_t i = 0; i < u.size(); ++i) deformed.X[i] += u[i];
    write_vtu(path, deformed, fields, vtu_format(output_.format));
}

void FrameWriter::write_surface(const std::string& path, std::span<const double> u, std::span<const double> v,
                                std::span<const double> f) {
    std::vector<double> positions = gather(scene_.mesh.X, surface_vertex_, 3);
    const std::vector<double> us = gather(u, surface_vertex_, 3);
    for (std::size_t i = 0; i < positions.size(); ++i) positions[i] += us[i];
    const std::vector<double> normals = vertex_normals(triangles_, positions);
    if (output_.format == OutputFormat::Ply) return write_ply(path, positions, triangles_, normals);
    if (output_.format == OutputFormat::Obj) return write_obj(path, positions, triangles_, normals);

    compute_cell_fields(u);
    const OutputFields& want = output_.fields;
    std::vector<double> vs, fs;
    if (want.velocity && !v.empty()) vs = gather(v, surface_vertex_, 3);
    if (want.force) fs = gather(f, surface_vertex_, 3);
    const std::vector<double> energy = gather(energy_density_, triangle_tet_, energy_density_.empty() ? 0 : 1);
    const std::vector<double> strain = gather(green_strain_, triangle_tet_, green_strain_.empty() ? 0 : 6);
    const std::vector<double> stress = gather(pk2_stress_, triangle_tet_, pk2_stress_.empty() ? 0 : 6);
    const std::vector<double> vm = gather(von_mises_, triangle_tet_, von_mises_.empty() ? 0 : 1);
    const auto ptr = [](const std::vector<double>& x) { return x.empty() ? nullptr : x.data(); };
    VtuFields fields;
    fields.displacement = want.displacement ? us.data() : nullptr;
    fields.velocity = ptr(vs);
    fields.force = ptr(fs);
    fields.normals = normals.data();
    fields.energy_density = ptr(energy);
    fields.green_strain = ptr(strain);
    fields.pk2_stress = ptr(stress);
    fields.von_mises = ptr(vm);
    fields.file_vertex = surface_file_vertex_.data();
    write_surface_vtu(path, positions, triangles_, triangle_region_, fields, vtu_format(output_.format));
}

}  // namespace edgefem::cli
