#include "edgefem/core/mesh.hpp"

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

double signed_volume(const double* a, const double* b, const double* c, const double* d) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
            u[2] * (v[0] * w[1] - v[1] * w[0])) /
           6.0;
}

}  // namespace edgefem
