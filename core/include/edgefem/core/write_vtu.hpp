// VTK XML output for ParaView: one .vtu per frame and a .pvd series file
// tying frames to times.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

// Binary (the default): every array zlib-compressed into the file's
// appended raw data (vtkZLibDataCompressor's blocks, UInt64 headers), about
// a quarter of the ASCII size; the doubles are the in-memory values bit for
// bit. Ascii: numbers in shortest round-trip form (also exact), diffable.
enum class VtuFormat { Binary, Ascii };

// Optional fields; a null pointer leaves the field out. Point fields have 3
// values per point, cell fields 1 (scalars) or 6 (symmetric tensors, in
// VTK's order XX, YY, ZZ, XY, YZ, XZ) per cell.
struct VtuFields {
    const double* displacement = nullptr;    // point; written as "displacement"
    const double* velocity = nullptr;        // point; "velocity"
    const double* force = nullptr;           // point; "force"
    const double* normals = nullptr;         // point; "normals" (surfaces)
    const double* energy_density = nullptr;  // cell: strain energy per rest volume (J/m^3)
    const double* green_strain = nullptr;    // cell, 6: the Green strain E
    const double* pk2_stress = nullptr;      // cell, 6: the second Piola-Kirchhoff stress (Pa)
    const double* von_mises = nullptr;       // cell: von Mises stress of the Cauchy stress (Pa)
    // Each point's 0-based index in the mesh file's vertex order, written as
    // the point field "file_vertex": for a volume when the numbering differs
    // from the file's (mesh_options.compact removed vertices), for a surface
    // always (its points are a subset).
    const index_t* file_vertex = nullptr;
};

// Writes an UnstructuredGrid with points X + displacement (rest positions when
// displacement is null), tets as VTK_TETRA, the region as cell data, and the
// given fields. The file is written whole or not at all (OutputFile): a
// failed write leaves no partial file. Throws IoError naming the file when
// it cannot be written.
void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields = {},
               VtuFormat format = VtuFormat::Binary);

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
