#include "edgefem/core/write_surface.hpp"

#include <bit>
#include <cstdint>
#include <cstring>

#include "edgefem/core/error.hpp"
#include "edgefem/core/output_file.hpp"
#include "vtk_piece.hpp"

namespace edgefem {

namespace {

std::size_t check_surface(const char* who, std::span<const double> positions,
                          std::span<const std::array<index_t, 3>> triangles, std::span<const double> normals) {
    if (positions.size() % 3 != 0)
        throw InvalidArgument(std::string(who) + ": positions has " + std::to_string(positions.size()) +
                              " values, not a multiple of 3");
    const std::size_t np = positions.size() / 3;
    if (!normals.empty() && normals.size() != positions.size())
        throw InvalidArgument(std::string(who) + ": normals has " + std::to_string(normals.size()) + " values, expected " +
                              std::to_string(positions.size()));
    for (std::size_t k = 0; k < triangles.size(); ++k)
        for (const index_t v : triangles[k])
            if (v < 0 || std::size_t(v) >= np)
                throw InvalidArgument(std::string(who) + ": triangle " + std::to_string(k) + " names point " +
                                      std::to_string(v) + ", outside 0.." + std::to_string(np) + " - 1");
    return np;
}

template <class T>
void put(std::string& out, T v) {
    static_assert(std::endian::native == std::endian::little, "PLY is written little endian");
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    out.append(b, sizeof(T));
}

}  // namespace

void write_ply(const std::string& path, std::span<const double> positions,
               std::span<const std::array<index_t, 3>> triangles, std::span<const double> normals) {
    const std::size_t np = check_surface("write_ply", positions, triangles, normals);
    std::string out = "ply\nformat binary_little_endian 1.0\ncomment edgefem surface\nelement vertex " +
                      std::to_string(np) + "\nproperty float x\nproperty float y\nproperty float z\n";
    if (!normals.empty()) out += "property float nx\nproperty float ny\nproperty float nz\n";
    out += "element face " + std::to_string(triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
    for (std::size_t v = 0; v < np; ++v) {
        for (int c = 0; c < 3; ++c) put(out, float(positions[3 * v + c]));
        if (!normals.empty())
            for (int c = 0; c < 3; ++c) put(out, float(normals[3 * v + c]));
    }
    for (const auto& t : triangles) {
        put(out, std::uint8_t(3));
        for (const index_t v : t) put(out, std::int32_t(v));
    }
    write_file_atomically(path, out);
}

void write_obj(const std::string& path, std::span<const double> positions,
               std::span<const std::array<index_t, 3>> triangles, std::span<const double> normals) {
    const std::size_t np = check_surface("write_obj", positions, triangles, normals);
    OutputFile file(path);
    std::string line = "# edgefem surface: " + std::to_string(np) + " vertices, " + std::to_string(triangles.size()) +
                       " triangles\n";
    const auto vector = [&](const char* tag, const double* x) {
        line += tag;
        for (int c = 0; c < 3; ++c) {
            line += ' ';
            line += detail::shortest(x[c]);
        }
        line += '\n';
    };
    for (std::size_t v = 0; v < np; ++v) vector("v", &positions[3 * v]);
    for (std::size_t v = 0; v < normals.size() / 3; ++v) vector("vn", &normals[3 * v]);
    file.write(line);
    line.clear();
    for (const auto& t : triangles) {
        line += 'f';
        for (const index_t v : t) {
            const std::string i = std::to_string(v + 1);
            line += ' ';
            line += i;
            if (!normals.empty()) {
                line += "//";
                line += i;
            }
        }
        line += '\n';
        if (line.size() > (1u << 16)) {
            file.write(line);
            line.clear();
        }
    }
    file.write(line);
    file.commit();
}

void write_surface_vtu(const std::string& path, std::span<const double> positions,
                       std::span<const std::array<index_t, 3>> triangles, std::span<const int> region,
                       const VtuFields& fields, VtuFormat format) {
    check_surface("write_surface_vtu", positions, triangles, {});
    if (region.size() != triangles.size())
        throw InvalidArgument("write_surface_vtu: region has " + std::to_string(region.size()) + " values for " +
                              std::to_string(triangles.size()) + " triangles");
    static_assert(sizeof(std::array<index_t, 3>) == 3 * sizeof(index_t));
    detail::write_cells(path, positions, {reinterpret_cast<const index_t*>(triangles.data()), 3 * triangles.size()}, 3,
                        5 /* VTK_TRIANGLE */, region, fields, format);
}

}  // namespace edgefem
