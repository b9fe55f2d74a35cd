// The frames `edgefem simulate` and `edgefem static` write (docs/scenes.md,
// "Output of edgefem simulate"): the tet mesh or its boundary surface, as
// VTU (compressed binary or ASCII), PLY or OBJ, with the fields
// OutputSettings::fields selects. Wiring only: the formulas are core's
// (tet_strain_stress, tet energies, vertex_normals).
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/tet_model.hpp"

namespace edgefem::cli {

class FrameWriter {
public:
    // `file_vertex` (SceneFile::file_vertex): when not empty, the mesh file's
    // numbering of the vertices, written as the point field "file_vertex".
    FrameWriter(const Scene& scene, const OutputSettings& output, std::vector<index_t> file_vertex = {});
    // u, v, f: 3 #V in the scene's numbering; v empty leaves the velocity
    // out (a static solve).
    void write(const std::string& path, std::span<const double> u, std::span<const double> v,
               std::span<const double> f);
    // ".vtu", ".ply" or ".obj".
    const char* extension() const { return file_extension(output_.format); }

private:
    void compute_cell_fields(std::span<const double> u);
    void write_surface(const std::string& path, std::span<const double> u, std::span<const double> v,
                       std::span<const double> f);

    const Scene& scene_;
    OutputSettings output_;
    std::vector<index_t> file_vertex_;
    std::optional<TetModel<double>> tets_;  // FE only: the SN has no per-tet strain or energy
    std::vector<double> energy_density_, green_strain_, pk2_stress_, von_mises_;  // per tet
    // The surface: its mesh vertices, triangles over them (0..P-1) and each
    // triangle's tet.
    std::vector<index_t> surface_vertex_, surface_file_vertex_;
    std::vector<std::array<index_t, 3>> triangles_;
    std::vector<index_t> triangle_tet_;
    std::vector<int> triangle_region_;
};

}  // namespace edgefem::cli
