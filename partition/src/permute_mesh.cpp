#include "edgefem/partition/permute_mesh.hpp"

#include <algorithm>
#include <array>
#include <numeric>

#include "edgefem/core/error.hpp"

namespace edgefem {

std::vector<index_t> invert_permutation(const std::vector<index_t>& new_of_old) {
    std::vector<index_t> old_of_new(new_of_old.size(), -1);
    for (std::size_t v = 0; v < new_of_old.size(); ++v) {
        const index_t n = new_of_old[v];
        if (n < 0 || std::size_t(n) >= new_of_old.size() || old_of_new[n] != -1)
            throw InvalidArgument("not a permutation: index " + std::to_string(n) + " at " + std::to_string(v));
        old_of_new[n] = static_cast<index_t>(v);
    }
    return old_of_new;
}

Mesh permute_mesh(const Mesh& mesh, const std::vector<index_t>& new_of_old) {
    const index_t nv = mesh.num_vertices(), nt = mesh.num_tets();
    const std::vector<index_t> old_of_new = invert_permutation(new_of_old);
    Mesh out;
    out.X.resize(mesh.X.size());
    for (index_t n = 0; n < nv; ++n)
        for (int r = 0; r < 3; ++r) out.X[3 * std::size_t(n) + r] = mesh.X[3 * std::size_t(old_of_new[n]) + r];
    // Tets renamed (vertex order inside a tet kept: orientation unchanged),
    // then ordered by their sorted new vertices.
    std::vector<std::array<index_t, 4>> sorted(nt);
    for (index_t t = 0; t < nt; ++t) {
        for (int k = 0; k < 4; ++k) sorted[t][k] = new_of_old[mesh.tets[4 * std::size_t(t) + k]];
        std::sort(sorted[t].begin(), sorted[t].end());
    }
    std::vector<index_t> tet_order(nt);
    std::iota(tet_order.begin(), tet_order.end(), 0);
    std::stable_sort(tet_order.begin(), tet_order.end(), [&](index_t a, index_t b) { return sorted[a] < sorted[b]; });
    out.tets.resize(mesh.tets.size());
    if (!mesh.region.empty()) out.region.resize(nt);
    const MeshSource& src = mesh.source;
    out.source.vertex_file = src.vertex_file;
    out.source.tet_file = src.tet_file;
    // Tagged triangles keep their order; their vertices are renamed.
    out.surfaces = mesh.surfaces;
    for (index_t& v : out.surfaces.vertices) v = new_of_old.at(v);
    out.source.triangle_file = src.triangle_file;
    out.source.triangle_line = src.triangle_line;
    auto permute_vertex_info = [&](const std::vector<std::int64_t>& in, std::vector<std::int64_t>& o) {
        if (in.size() != std::size_t(nv)) return;
        o.resize(nv);
        for (index_t n = 0; n < nv; ++n) o[n] = in[old_of_new[n]];
    };
    permute_vertex_info(src.vertex_line, out.source.vertex_line);
    permute_vertex_info(src.vertex_id, out.source.vertex_id);
    const bool tet_lines = src.tet_line.size() == std::size_t(nt), tet_ids = src.tet_id.size() == std::size_t(nt);
    if (tet_lines) out.source.tet_line.resize(nt);
    if (tet_ids) out.source.tet_id.resize(nt);
    for (index_t k = 0; k < nt; ++k) {
        const index_t t = tet_order[k];
        for (int c = 0; c < 4; ++c) out.tets[4 * std::size_t(k) + c] = new_of_old[mesh.tets[4 * std::size_t(t) + c]];
        if (!mesh.region.empty()) out.region[k] = mesh.region[t];
        if (tet_lines) out.source.tet_line[k] = src.tet_line[t];
        if (tet_ids) out.source.tet_id[k] = src.tet_id[t];
    }
    return out;
}

}  // namespace edgefem
