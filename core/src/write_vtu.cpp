// VTK XML writer. ASCII, with numbers in shortest round-trip form
// (std::to_chars), so values read back bit-exact and files stay diffable.
// Every file is written through an OutputFile: a failed write leaves no
// partial file, and a .pvd is replaced in one step, never truncated.
#include "edgefem/core/write_vtu.hpp"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/output_file.hpp"
#include "edgefem/core/validate_mesh.hpp"

namespace edgefem {

namespace {

// Numbers in shortest round-trip form into an OutputFile (written whole or
// not at all); every failure throws IoError naming the path.
class Output {
public:
    explicit Output(const std::string& path) : file_(path) {}

    Output& operator<<(std::string_view s) {
        file_.write(s);
        return *this;
    }
    Output& operator<<(double x) { return number(x); }
    Output& operator<<(long long x) { return number(x); }

    void close() { file_.commit(); }

private:
    template <class T>
    Output& number(T x) {
        char tmp[32];
        const auto [end, ec] = std::to_chars(tmp, tmp + sizeof tmp - 1, x);
        char* last = ec == std::errc() ? end : tmp;
        *last++ = ' ';
        file_.write(std::string_view(tmp, static_cast<std::size_t>(last - tmp)));
        return *this;
    }

    OutputFile file_;
};

void vector_array(Output& out, const char* name, const double* data, index_t nv) {
    out << "        <DataArray type=\"Float64\" Name=\"" << name
        << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < 3 * static_cast<std::size_t>(nv); ++i) {
        out << data[i];
        if (i % 3 == 2) out << "\n";
    }
    out << "        </DataArray>\n";
}

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

void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields) {
    check_mesh_indices(mesh);  // connectivity inside the mesh, before a byte is written
    const index_t nv = mesh.num_vertices(), nt = mesh.num_tets();
    Output out(path);
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
           "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << std::to_string(nv) << "\" NumberOfCells=\""
        << std::to_string(nt) << "\">\n";

    if (fields.displacement || fields.force || fields.file_vertex) {
        out << "      <PointData";
        if (fields.displacement || fields.force)
            out << " Vectors=\"" << (fields.displacement ? "displacement" : "force") << "\"";
        out << ">\n";
        if (fields.displacement) vector_array(out, "displacement", fields.displacement, nv);
        if (fields.force) vector_array(out, "force", fields.force, nv);
        if (fields.file_vertex) {
            out << "        <DataArray type=\"Int64\" Name=\"file_vertex\" format=\"ascii\">\n";
            for (index_t v = 0; v < nv; ++v) {
                out << static_cast<long long>(fields.file_vertex[v]);
                if (v % 16 == 15 || v + 1 == nv) out << "\n";
            }
            out << "        </DataArray>\n";
        }
        out << "      </PointData>\n";
    }

    out << "      <CellData Scalars=\"region\">\n"
           "        <DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n";
    for (index_t t = 0; t < nt; ++t) {
        out << static_cast<long long>(mesh.tet_region(t));
        if (t % 16 == 15 || t + 1 == nt) out << "\n";
    }
    out << "        </DataArray>\n";
    if (fields.energy_density) {
        out << "        <DataArray type=\"Float64\" Name=\"energy_density\" format=\"ascii\">\n";
        for (index_t t = 0; t < nt; ++t) {
            out << fields.energy_density[t];
            if (t % 8 == 7 || t + 1 == nt) out << "\n";
        }
        out << "        </DataArray>\n";
    }
    out << "      </CellData>\n";

    // Points are the deformed positions X + u.
    out << "      <Points>\n"
           "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < 3 * static_cast<std::size_t>(nv); ++i) {
        out << mesh.X[i] + (fields.displacement ? fields.displacement[i] : 0.0);
        if (i % 3 == 2) out << "\n";
    }
    out << "        </DataArray>\n"
           "      </Points>\n"
           "      <Cells>\n"
           "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < mesh.tets.size(); ++i) {
        out << static_cast<long long>(mesh.tets[i]);
        if (i % 4 == 3) out << "\n";
    }
    out << "        </DataArray>\n"
           "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (index_t t = 0; t < nt; ++t) {
        out << 4 * (static_cast<long long>(t) + 1);
        if (t % 16 == 15 || t + 1 == nt) out << "\n";
    }
    out << "        </DataArray>\n"
           "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (index_t t = 0; t < nt; ++t) {
        out << 10LL;  // VTK_TETRA
        if (t % 32 == 31 || t + 1 == nt) out << "\n";
    }
    out << "        </DataArray>\n"
           "      </Cells>\n"
           "    </Piece>\n"
           "  </UnstructuredGrid>\n"
           "</VTKFile>\n";
    out.close();
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
    Output out(path_);
    out << "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "  <Collection>\n";
    for (const auto& [time, file] : frames_) {
        char t[32];
        const auto [end, ec] = std::to_chars(t, t + sizeof t, time);
        out << "    <DataSet timestep=\"" << std::string_view(t, ec == std::errc() ? end - t : 0)
            << "\" group=\"\" part=\"0\" file=\"" << xml_escape(file) << "\"/>\n";
    }
    out << "  </Collection>\n"
           "</VTKFile>\n";
    out.close();
}

}  // namespace edgefem
