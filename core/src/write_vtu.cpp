// VTK XML writer: the mesh and fields become the arrays of one piece
// (vtk_piece.cpp writes them ASCII or compressed binary). Every file is
// written through an OutputFile: a failed write leaves no partial file, and
// a .pvd is replaced in one step, never truncated.
#include "edgefem/core/write_vtu.hpp"

#include <cstdint>
#include <filesystem>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/output_file.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "vtk_piece.hpp"

namespace edgefem {

namespace {

std::string xml_escape(const std::string& s) {
    std::string out;
    for (const char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

}  // namespace

void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields, VtuFormat format) {
    check_mesh_indices(mesh);  // connectivity inside the mesh, before a byte is written
    // Points are the deformed positions X + u.
    std::vector<double> points(mesh.X);
    if (fields.displacement)
        for (std::size_t i = 0; i < points.size(); ++i) points[i] += fields.displacement[i];
    std::vector<int> region(mesh.region);
    if (region.empty()) region.assign(std::size_t(mesh.num_tets()), 0);
    detail::write_cells(path, points, mesh.tets, 4, 10 /* VTK_TETRA */, region, fields, format);
}

PvdSeries::PvdSeries(std::string pvd_path) : path_(std::move(pvd_path)) {}

PvdSeries::~PvdSeries() {
    try {
        write();
    } catch (...) {
        // A destructor must not throw; callers who care call write() themselves.
    }
}

void PvdSeries::add(double time, const std::string& vtu_path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path dir = fs::absolute(fs::path(path_), ec).parent_path().lexically_normal();
    const fs::path vtu = fs::absolute(fs::path(vtu_path), ec).lexically_normal();
    const fs::path rel = vtu.lexically_relative(dir);
    // Inside the .pvd's folder: relative, so the series can be moved as a whole.
    const bool inside = !ec && !rel.empty() && *rel.begin() != "..";
    frames_.emplace_back(time, inside ? rel.generic_string() : vtu.generic_string());
}

void PvdSeries::write() const {
    std::string xml =
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        "  <Collection>\n";
    for (const auto& [time, file] : frames_)
        xml += "    <DataSet timestep=\"" + detail::shortest(time) + "\" group=\"\" part=\"0\" file=\"" +
               xml_escape(file) + "\"/>\n";
    xml += "  </Collection>\n"
           "</VTKFile>\n";
    write_file_atomically(path_, xml);
}

}  // namespace edgefem
