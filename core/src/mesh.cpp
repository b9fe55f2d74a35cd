#include "edgefem/core/mesh.hpp"

#include "edgefem/physics/tet_volume.hpp"

namespace edgefem {

namespace {
std::string describe(const char* kind, index_t i, const std::string& file,
                     const std::vector<std::int64_t>& line, const std::vector<std::int64_t>& id) {
    // append() rather than "literal" + string: g++ 12 warns falsely (-Wrestrict) on the latter.
    std::string out(kind);
    out.append(" ").append(std::to_string(i));
    if (static_cast<std::size_t>(i) < id.size() && id[i] != i)
        out.append(" (numbered ").append(std::to_string(id[i])).append(" in the file)");
    if (!file.empty()) {
        out.append(" at ").append(file);
        if (static_cast<std::size_t>(i) < line.size()) out.append(":").append(std::to_string(line[i]));
    }
    return out;
}
}  // namespace

std::string Mesh::describe_tet(index_t t) const {
    return describe("tet", t, source.tet_file, source.tet_line, source.tet_id);
}

std::string Mesh::describe_vertex(index_t v) const {
    return describe("vertex", v, source.vertex_file, source.vertex_line, source.vertex_id);
}

std::string Mesh::describe_triangle(std::size_t k) const {
    return describe("triangle", static_cast<index_t>(k), source.triangle_file, source.triangle_line, {});
}

double signed_volume(const double* a, const double* b, const double* c, const double* d) {
    return physics::tet_signed_volume(a, b, c, d);
}

}  // namespace edgefem
