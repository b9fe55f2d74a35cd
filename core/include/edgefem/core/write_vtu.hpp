// VTK XML output for ParaView: one .vtu per frame and a .pvd series file
// tying frames to times.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// Optional fields; a null pointer leaves the field out.
struct VtuFields {
    const double* displacement = nullptr;    // 3 * #V; written as "displacement"
    const double* force = nullptr;           // 3 * #V; written as "force"
    const double* energy_density = nullptr;  // #T strain energy per rest volume (J/m^3)
    // #V: each vertex's 0-based index in the mesh file's vertex order, when
    // the numbering differs from it (mesh_options.compact removed vertices);
    // written as the point field "file_vertex".
    const index_t* file_vertex = nullptr;
};

// Writes an UnstructuredGrid with points X + displacement (rest positions when
// displacement is null), tets as VTK_TETRA, the region as cell data, and the
// given fields. The file is written whole or not at all (OutputFile): a
// failed write leaves no partial file. Throws IoError naming the file when
// it cannot be written.
void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields = {});

// A .pvd collection: add() frames as they are written, write() (also called
// by the destructor, errors swallowed there) replaces the .pvd file in one
// step (OutputFile), so a full disk or a kill leaves the previous series.
class PvdSeries {
public:
    explicit PvdSeries(std::string pvd_path);
    ~PvdSeries();
    PvdSeries(const PvdSeries&) = delete;
    PvdSeries& operator=(const PvdSeries&) = delete;

    // `vtu_path` is stored relative to the .pvd file's folder when it lies in it.
    void add(double time, const std::string& vtu_path);
    void write() const;

private:
    std::string path_;
    std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace edgefem
