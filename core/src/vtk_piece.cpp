#include "vtk_piece.hpp"

#include <zlib.h>

#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/output_file.hpp"

namespace edgefem::detail {

static_assert(std::endian::native == std::endian::little, "the VTU writer assumes a little-endian host");

namespace {

enum class VtkType { Float64, Int32, Int64, UInt8 };

// `count` values of `type` at `data` (little-endian host order),
// `components` per tuple; `name` empty: no Name attribute.
struct VtkArray {
    std::string name;
    VtkType type;
    int components;
    const void* data;
    std::size_t count;
};

struct VtkPiece {
    std::size_t points = 0, cells = 0;
    std::vector<VtkArray> point_data, cell_data;
    // The active attributes, e.g. Vectors="displacement" (without the
    // leading space); empty: none.
    std::string point_attributes, cell_attributes;
    VtkArray positions, connectivity, offsets, types;
};

// vtkZLibDataCompressor's default block size (VTK's vtkXMLWriter::BlockSize).
constexpr std::size_t kBlockSize = 32768;
// Doubles barely compress, whatever the level: the built-in beam's frame
// (1.25 MB of arrays) becomes 753 KB at level 1 in 0.16 s and 751 KB at
// level 6 in 0.39 s (2 shared vCPUs, 2026-11-27).
constexpr int kLevel = Z_BEST_SPEED;

const char* type_name(VtkType t) {
    switch (t) {
        case VtkType::Float64: return "Float64";
        case VtkType::Int32: return "Int32";
        case VtkType::Int64: return "Int64";
        case VtkType::UInt8: return "UInt8";
    }
    return "";
}

std::size_t type_size(VtkType t) {
    switch (t) {
        case VtkType::Float64: return 8;
        case VtkType::Int32: return 4;
        case VtkType::Int64: return 8;
        case VtkType::UInt8: return 1;
    }
    return 0;
}

template <class T>
void append_number(std::string& out, T x) {
    char tmp[32];
    const auto [end, ec] = std::to_chars(tmp, tmp + sizeof tmp, x);
    if (ec == std::errc()) out.append(tmp, end);
}

// ASCII: numbers separated by spaces, a tuple per line for vectors and
// tensors, several scalars per line otherwise.
void ascii_values(OutputFile& file, const VtkArray& a) {
    const std::size_t per_line = a.components > 1 ? std::size_t(a.components)
                                 : a.type == VtkType::Float64 ? 8
                                 : a.type == VtkType::UInt8   ? 32
                                                              : 16;
    std::string line;
    for (std::size_t i = 0; i < a.count; ++i) {
        switch (a.type) {
            case VtkType::Float64: append_number(line, static_cast<const double*>(a.data)[i]); break;
            case VtkType::Int32: append_number(line, static_cast<const std::int32_t*>(a.data)[i]); break;
            case VtkType::Int64: append_number(line, static_cast<const std::int64_t*>(a.data)[i]); break;
            case VtkType::UInt8: append_number(line, int(static_cast<const std::uint8_t*>(a.data)[i])); break;
        }
        line += ' ';
        if (i % per_line == per_line - 1 || i + 1 == a.count) {
            line += '\n';
            file.write(line);
            line.clear();
        }
    }
}

void append_u64(std::string& out, std::uint64_t v) {
    char b[8];
    std::memcpy(b, &v, 8);
    out.append(b, 8);
}

// The array's bytes as vtkZLibDataCompressor writes them: UInt64 header
// [#blocks, block size, size of the last partial block (0: the last block is
// full), compressed size of each block], then the compressed blocks.
std::string compressed_block(const std::string& path, const VtkArray& a) {
    const std::size_t bytes = a.count * type_size(a.type);
    const std::size_t nblocks = (bytes + kBlockSize - 1) / kBlockSize;
    const auto* src = static_cast<const Bytef*>(a.data);
    std::string body;
    std::vector<std::uint64_t> sizes(nblocks);
    std::vector<Bytef> buf(compressBound(kBlockSize));
    for (std::size_t b = 0; b < nblocks; ++b) {
        const std::size_t n = std::min(kBlockSize, bytes - b * kBlockSize);
        uLongf out_len = uLongf(buf.size());
        if (compress2(buf.data(), &out_len, src + b * kBlockSize, uLong(n), kLevel) != Z_OK)
            throw IoError("cannot write '" + path + "': zlib failed to compress the array '" + a.name + "'", path);
        sizes[b] = out_len;
        body.append(reinterpret_cast<const char*>(buf.data()), out_len);
    }
    std::string out;
    append_u64(out, nblocks);
    append_u64(out, kBlockSize);
    append_u64(out, bytes % kBlockSize);
    for (const std::uint64_t s : sizes) append_u64(out, s);
    return out + body;
}

class PieceWriter {
public:
    PieceWriter(const std::string& path, VtuFormat format) : file_(path), format_(format) {}

    void array(const VtkArray& a, const char* indent = "        ") {
        std::string tag = std::string(indent) + "<DataArray type=\"" + type_name(a.type) + "\"";
        if (!a.name.empty()) tag += " Name=\"" + a.name + "\"";
        if (a.components > 1) tag += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
        if (format_ == VtuFormat::Ascii) {
            file_.write(tag + " format=\"ascii\">\n");
            ascii_values(file_, a);
            file_.write(std::string(indent) + "</DataArray>\n");
        } else {
            file_.write(tag + " format=\"appended\" offset=\"" + std::to_string(appended_.size()) + "\"/>\n");
            appended_ += compressed_block(file_.path(), a);
        }
    }
    void text(std::string_view s) { file_.write(s); }
    void finish() {
        if (format_ == VtuFormat::Binary) {
            file_.write("  <AppendedData encoding=\"raw\">\n   _");
            file_.write(appended_);
            file_.write("\n  </AppendedData>\n");
        }
        file_.write("</VTKFile>\n");
        file_.commit();
    }

private:
    OutputFile file_;
    VtuFormat format_;
    std::string appended_;
};

void data_section(PieceWriter& w, const char* tag, const std::string& attributes, const std::vector<VtkArray>& arrays) {
    if (arrays.empty()) return;
    w.text(std::string("      <") + tag + (attributes.empty() ? "" : " " + attributes) + ">\n");
    for (const VtkArray& a : arrays) w.array(a);
    w.text(std::string("      </") + tag + ">\n");
}

// The fields' arrays, `points` and `cells` long, into the piece; `file_vertex`
// holds its Int64 copy.
void add_fields(VtkPiece& piece, const VtuFields& f, std::vector<std::int64_t>& file_vertex) {
    const std::size_t np = piece.points, nc = piece.cells;
    const auto point = [&](const char* name, const double* d) {
        if (d) piece.point_data.push_back({name, VtkType::Float64, 3, d, 3 * np});
    };
    point("displacement", f.displacement);
    point("velocity", f.velocity);
    point("force", f.force);
    point("normals", f.normals);
    if (f.displacement || f.force) piece.point_attributes = std::string("Vectors=\"") + (f.displacement ? "displacement" : "force") + "\"";
    if (f.normals) piece.point_attributes += std::string(piece.point_attributes.empty() ? "" : " ") + "Normals=\"normals\"";
    if (f.file_vertex) {
        file_vertex.assign(f.file_vertex, f.file_vertex + np);
        piece.point_data.push_back({"file_vertex", VtkType::Int64, 1, file_vertex.data(), np});
    }
    const auto cell = [&](const char* name, int components, const double* d) {
        if (d) piece.cell_data.push_back({name, VtkType::Float64, components, d, std::size_t(components) * nc});
    };
    cell("energy_density", 1, f.energy_density);
    cell("green_strain", 6, f.green_strain);
    cell("pk2_stress", 6, f.pk2_stress);
    cell("von_mises", 1, f.von_mises);
}

// Offsets and types of `cells` cells of `size` vertices and VTK type `type`.
struct CellArrays {
    std::vector<std::int64_t> offsets;
    std::vector<std::uint8_t> types;
    CellArrays(std::size_t cells, int size, std::uint8_t type) : offsets(cells), types(cells, type) {
        for (std::size_t c = 0; c < cells; ++c) offsets[c] = std::int64_t(size) * std::int64_t(c + 1);
    }
};

void write_vtk_piece(const std::string& path, const VtkPiece& piece, VtuFormat format) {
    PieceWriter w(path, format);
    w.text("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\"");
    w.text(format == VtuFormat::Binary ? " header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n" : ">\n");
    w.text("  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(piece.points) + "\" NumberOfCells=\"" +
           std::to_string(piece.cells) + "\">\n");
    data_section(w, "PointData", piece.point_attributes, piece.point_data);
    data_section(w, "CellData", piece.cell_attributes, piece.cell_data);
    w.text("      <Points>\n");
    w.array(piece.positions);
    w.text("      </Points>\n      <Cells>\n");
    w.array(piece.connectivity);
    w.array(piece.offsets);
    w.array(piece.types);
    w.text("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
    w.finish();
}

}  // namespace

void write_cells(const std::string& path, std::span<const double> positions, std::span<const index_t> connectivity,
                 int size, std::uint8_t type, std::span<const int> region, const VtuFields& fields, VtuFormat format) {
    static_assert(sizeof(index_t) == 4 && sizeof(int) == 4, "connectivity and regions are written as Int32");
    VtkPiece piece;
    piece.points = positions.size() / 3;
    piece.cells = connectivity.size() / std::size_t(size);
    const CellArrays cells(piece.cells, size, type);
    piece.cell_data.push_back({"region", VtkType::Int32, 1, region.data(), piece.cells});
    piece.cell_attributes = "Scalars=\"region\"";
    std::vector<std::int64_t> file_vertex;
    add_fields(piece, fields, file_vertex);
    piece.positions = {"", VtkType::Float64, 3, positions.data(), 3 * piece.points};
    piece.connectivity = {"connectivity", VtkType::Int32, 1, connectivity.data(), connectivity.size()};
    piece.offsets = {"offsets", VtkType::Int64, 1, cells.offsets.data(), piece.cells};
    piece.types = {"types", VtkType::UInt8, 1, cells.types.data(), piece.cells};
    write_vtk_piece(path, piece, format);
}

std::string shortest(double x) {
    std::string s;
    append_number(s, x);
    return s;
}

}  // namespace edgefem::detail
