// Format dispatch for read_mesh: by extension, or a TetGen prefix when
// "<path>.node" exists.
#include <filesystem>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/read_mesh.hpp"

namespace edgefem {

namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return ext;
}

MeshFormat detect(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".node" || ext == ".ele") return MeshFormat::TetGen;
    if (ext == ".msh") return MeshFormat::Gmsh;
    if (ext == ".mesh") return MeshFormat::Medit;
    if (ext == ".veg") return MeshFormat::Vega;
    if (ext == ".meshb") throw MeshError("binary MEDIT (.meshb) is not supported", path);
    std::error_code ec;
    if (std::filesystem::exists(path + ".node", ec) || std::filesystem::exists(path + ".NODE", ec))
        return MeshFormat::TetGen;
    throw MeshError(
        "cannot tell the mesh format: expected a .node/.ele (or their common prefix), .msh, "
        ".mesh or .veg file",
        path);
}

}  // namespace

Mesh read_mesh(const std::string& path, MeshFormat format, ReadReport* report) {
    if (format == MeshFormat::Auto) format = detect(path);
    switch (format) {
        case MeshFormat::TetGen: return read_tetgen(path, report);
        case MeshFormat::Gmsh: return read_gmsh(path, report);
        case MeshFormat::Medit: return read_medit(path, report);
        case MeshFormat::Vega: return read_vega(path, report);
        case MeshFormat::Auto: break;
    }
    throw InvalidArgument("read_mesh: unknown mesh format");
}

}  // namespace edgefem
