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
};

// Writes an UnstructuredGrid with points X + displacement (rest positions when
// displacement is null), tets as VTK_TETRA, the region as cell data, and the
// given fields. Throws Error when the file cannot be written.
void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields = {});

// A .pvd collection: add() frames as they are written, write() (also called
// by the destructor, errors swallowed there) updates the .pvd file.
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
