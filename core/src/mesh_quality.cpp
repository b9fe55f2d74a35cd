#include "edgefem/core/mesh_quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace edgefem {

namespace {

struct Vec {
    double x, y, z;
};
Vec sub(const double* a, const double* b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec cross(Vec a, Vec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

}  // namespace

MeshQuality mesh_quality(const Mesh& mesh) {
    MeshQuality q;
    const index_t nv = mesh.num_vertices(), nt = mesh.num_tets();
    if (nv > 0) {
        constexpr double inf = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 3; ++k) {
            q.bbox_min[k] = inf;
            q.bbox_max[k] = -inf;
        }
        for (index_t v = 0; v < nv; ++v)
            for (int k = 0; k < 3; ++k) {
                const double x = mesh.X[3 * static_cast<std::size_t>(v) + k];
                q.bbox_min[k] = std::min(q.bbox_min[k], x);
                q.bbox_max[k] = std::max(q.bbox_max[k], x);
            }
    }
    if (nt == 0) return q;

    q.min_volume = std::numeric_limits<double>::infinity();
    q.max_volume = -std::numeric_limits<double>::infinity();
    double min_cos = 2, max_cos = -2;  // cosines of the interior dihedral angles
    for (index_t t = 0; t < nt; ++t) {
        const index_t* tet = &mesh.tets[4 * static_cast<std::size_t>(t)];
        if (std::any_of(tet, tet + 4, [&](index_t v) { return v < 0 || v >= nv; }))
            continue;  // not validated; nothing sensible to measure
        const double* p[4];
        for (int k = 0; k < 4; ++k) p[k] = &mesh.X[3 * static_cast<std::size_t>(tet[k])];
        const double vol = signed_volume(p[0], p[1], p[2], p[3]);
        q.min_volume = std::min(q.min_volume, vol);
        q.max_volume = std::max(q.max_volume, vol);
        q.total_volume += vol;

        // Outward unit normal of the face opposite each vertex; the dihedral
        // angle at the edge shared by faces i and j is pi - angle(n_i, n_j).
        Vec n[4];
        bool flat = false;
        for (int k = 0; k < 4; ++k) {
            const double* a = p[(k + 1) % 4];
            const double* b = p[(k + 2) % 4];
            const double* c = p[(k + 3) % 4];
            Vec m = cross(sub(b, a), sub(c, a));
            if (dot(m, sub(p[k], a)) > 0) m = {-m.x, -m.y, -m.z};
            const double len = std::sqrt(dot(m, m));
            if (!(len > 0)) flat = true;
            n[k] = {m.x / len, m.y / len, m.z / len};
        }
        if (flat) continue;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                const double c = std::clamp(-dot(n[i], n[j]), -1.0, 1.0);
                min_cos = std::min(min_cos, c);
                max_cos = std::max(max_cos, c);
            }
    }
    if (max_cos >= -1) {  // at least one non-flat tet
        q.min_dihedral_deg = std::acos(max_cos) * 180.0 / std::numbers::pi;
        q.max_dihedral_deg = std::acos(min_cos) * 180.0 / std::numbers::pi;
    }
    return q;
}

}  // namespace edgefem
