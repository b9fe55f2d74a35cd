#include "edgefem/core/surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "edgefem/core/error.hpp"
#include "edgefem/core/surface_selection.hpp"
#include "edgefem/core/validate_mesh.hpp"

namespace edgefem {

namespace {

const double* vertex(const Mesh& m, index_t v) { return &m.X[3 * std::size_t(v)]; }

void sub(const double* a, const double* b, double* d) {
    for (int i = 0; i < 3; ++i) d[i] = a[i] - b[i];
}
void cross(const double* a, const double* b, double* c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Barycentric weights of p in tet t and their gradients' lengths; false for
// a degenerate tet.
bool barycentric(const Mesh& m, index_t t, const double* p, std::array<double, 4>& w, std::array<double, 4>& grad_len) {
    const index_t* v = &m.tets[4 * std::size_t(t)];
    double e[3][3], d[3];
    for (int c = 0; c < 3; ++c) sub(vertex(m, v[c + 1]), vertex(m, v[0]), e[c]);
    sub(p, vertex(m, v[0]), d);
    // Rows of the inverse of [e0 e1 e2] (columns): (e1 x e2, e2 x e0, e0 x e1) / det.
    double r[3][3];
    cross(e[1], e[2], r[0]);
    cross(e[2], e[0], r[1]);
    cross(e[0], e[1], r[2]);
    const double det = dot(e[0], r[0]);
    if (!(std::abs(det) > 0)) return false;
    double g0[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 3; ++i) r[k][i] /= det;
        w[k + 1] = dot(r[k], d);
        grad_len[k + 1] = std::sqrt(dot(r[k], r[k]));
        for (int i = 0; i < 3; ++i) g0[i] -= r[k][i];
    }
    w[0] = 1 - w[1] - w[2] - w[3];
    grad_len[0] = std::sqrt(dot(g0, g0));
    return true;
}

// A uniform grid over the mesh's bounding box; cell c lists the tets whose
// bounding boxes overlap it.
struct TetGrid {
    double lo[3], h[3];
    int n[3];
    std::vector<index_t> first, item;

    explicit TetGrid(const Mesh& m) {
        double hi[3];
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::numeric_limits<double>::max();
            hi[i] = -lo[i];
        }
        for (std::size_t k = 0; k < m.X.size(); ++k) {
            lo[k % 3] = std::min(lo[k % 3], m.X[k]);
            hi[k % 3] = std::max(hi[k % 3], m.X[k]);
        }
        const double cells = std::max(1.0, double(m.num_tets()) / 4);
        const double ext[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        const double vol = std::max(ext[0], 1e-300) * std::max(ext[1], 1e-300) * std::max(ext[2], 1e-300);
        const double side = std::cbrt(vol / cells);
        for (int i = 0; i < 3; ++i) {
            n[i] = int(std::clamp(std::ceil(ext[i] / side), 1.0, 1024.0));
            h[i] = ext[i] > 0 ? ext[i] / n[i] : 1.0;
        }
        std::vector<std::array<int, 6>> box(std::size_t(m.num_tets()));
        first.assign(std::size_t(n[0]) * n[1] * n[2] + 1, 0);
        for (index_t t = 0; t < m.num_tets(); ++t) {
            auto& b = box[t];
            for (int i = 0; i < 3; ++i) {
                double a = std::numeric_limits<double>::max(), z = -a;
                for (int k = 0; k < 4; ++k) {
                    const double x = vertex(m, m.tets[4 * std::size_t(t) + k])[i];
                    a = std::min(a, x);
                    z = std::max(z, x);
                }
                b[i] = cell(a, i);
                b[3 + i] = cell(z, i);
            }
            for_cells(b, [&](std::size_t c) { ++first[c + 1]; });
        }
        for (std::size_t c = 1; c < first.size(); ++c) first[c] += first[c - 1];
        item.resize(std::size_t(first.back()));
        std::vector<index_t> next(first.begin(), first.end() - 1);
        for (index_t t = 0; t < m.num_tets(); ++t) for_cells(box[t], [&](std::size_t c) { item[next[c]++] = t; });
    }
    int cell(double x, int i) const { return std::clamp(int(std::floor((x - lo[i]) / h[i])), 0, n[i] - 1); }
    template <class F>
    void for_cells(const std::array<int, 6>& b, F&& f) const {
        for (int z = b[2]; z <= b[5]; ++z)
            for (int y = b[1]; y <= b[4]; ++y)
                for (int x = b[0]; x <= b[3]; ++x) f((std::size_t(z) * n[1] + y) * n[0] + x);
    }
};

}  // namespace

std::vector<index_t> BoundarySurface::vertices() const { return triangle_vertices(triangles); }

BoundarySurface boundary_surface(const Mesh& mesh) {
    check_mesh_indices(mesh);
    struct Face {
        std::array<index_t, 3> key;
        index_t tet;
        int opposite;  // local vertex
    };
    std::vector<Face> faces;
    faces.reserve(mesh.tets.size());
    for (index_t t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k) {
            std::array<index_t, 3> f;
            for (int j = 0, c = 0; j < 4; ++j)
                if (j != k) f[c++] = mesh.tets[4 * std::size_t(t) + j];
            std::sort(f.begin(), f.end());
            faces.push_back({f, t, k});
        }
    std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
        return a.key != b.key ? a.key < b.key : a.tet < b.tet;
    });
    BoundarySurface s;
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i + 1;
        while (j < faces.size() && faces[j].key == faces[i].key) ++j;
        if (j - i == 1) {
            const Face& f = faces[i];
            std::array<index_t, 3> tri;
            for (int q = 0, c = 0; q < 4; ++q)
                if (q != f.opposite) tri[c++] = mesh.tets[4 * std::size_t(f.tet) + q];
            const index_t d = mesh.tets[4 * std::size_t(f.tet) + f.opposite];
            double ab[3], ac[3], ad[3], nrm[3];
            sub(vertex(mesh, tri[1]), vertex(mesh, tri[0]), ab);
            sub(vertex(mesh, tri[2]), vertex(mesh, tri[0]), ac);
            sub(vertex(mesh, d), vertex(mesh, tri[0]), ad);
            cross(ab, ac, nrm);
            if (dot(nrm, ad) > 0) std::swap(tri[1], tri[2]);  // the normal pointed into the tet
            s.triangles.push_back(tri);
            s.tet.push_back(f.tet);
        }
        i = j;
    }
    return s;
}

Embedding embed_points(const Mesh& mesh, std::span<const double> points) {
    if (points.size() % 3 != 0)
        throw InvalidArgument("embed_points: " + std::to_string(points.size()) +
                              " coordinates, not a multiple of 3 (x, y, z per point)");
    for (std::size_t k = 0; k < points.size(); ++k)
        if (!std::isfinite(points[k]))
            throw InvalidArgument("embed_points: point " + std::to_string(k / 3) + " has a non-finite coordinate");
    if (mesh.num_tets() == 0) throw MeshError("embed_points: the mesh has no tets");
    check_mesh_indices(mesh);
    const TetGrid grid(mesh);
    const std::size_t np = points.size() / 3;
    Embedding e;
    e.tet.resize(np);
    e.weight.resize(np);
    e.outside.resize(np);
    const int rings = std::max({grid.n[0], grid.n[1], grid.n[2]});
    for (std::size_t p = 0; p < np; ++p) {
        const double* x = &points[3 * p];
        int c[3];
        for (int i = 0; i < 3; ++i) c[i] = grid.cell(x[i], i);
        double best = std::numeric_limits<double>::max();
        int found_ring = -1;
        // Rings of cells around the point's (clamped) cell, until a tet
        // holds it, or one ring past the first that had tets.
        for (int r = 0; r <= rings && best > 0 && (found_ring < 0 || r <= found_ring + 1); ++r) {
            const std::array<int, 6> b = {std::max(c[0] - r, 0), std::max(c[1] - r, 0), std::max(c[2] - r, 0),
                                          std::min(c[0] + r, grid.n[0] - 1), std::min(c[1] + r, grid.n[1] - 1),
                                          std::min(c[2] + r, grid.n[2] - 1)};
            grid.for_cells(b, [&](std::size_t cell) {
                for (index_t k = grid.first[cell]; k < grid.first[cell + 1]; ++k) {
                    std::array<double, 4> w, g;
                    const index_t t = grid.item[k];
                    if (!barycentric(mesh, t, x, w, g)) continue;
                    double dist = 0;
                    for (int q = 0; q < 4; ++q)
                        if (w[q] < 0) dist = std::max(dist, -w[q] / g[q]);
                    if (dist < best || (dist == best && t < e.tet[p])) {
                        best = dist;
                        e.tet[p] = t;
                        e.weight[p] = w;
                    }
                    if (found_ring < 0) found_ring = r;
                }
            });
        }
        e.outside[p] = best;
    }
    return e;
}

template <class S>
void embedded_positions(const Mesh& mesh, const Embedding& e, std::span<const S> u, std::span<double> out) {
    if (u.size() != mesh.X.size())
        throw InvalidArgument("embedded_positions: u has " + std::to_string(u.size()) + " values, the mesh " +
                              std::to_string(mesh.X.size()) + " (3 per vertex)");
    if (out.size() != 3 * e.tet.size())
        throw InvalidArgument("embedded_positions: out has " + std::to_string(out.size()) + " values, the embedding " +
                              std::to_string(3 * e.tet.size()) + " (3 per point)");
    for (std::size_t p = 0; p < e.tet.size(); ++p)
        for (int i = 0; i < 3; ++i) {
            double s = 0;
            for (int k = 0; k < 4; ++k) {
                const std::size_t v = std::size_t(mesh.tets[4 * std::size_t(e.tet[p]) + k]);
                s += e.weight[p][k] * (mesh.X[3 * v + i] + double(u[3 * v + i]));
            }
            out[3 * p + i] = s;
        }
}

std::vector<double> vertex_normals(std::span<const std::array<index_t, 3>> triangles, std::span<const double> positions) {
    std::vector<double> n(positions.size(), 0.0);
    const std::size_t nv = positions.size() / 3;
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        const auto& t = triangles[k];
        for (index_t v : t)
            if (v < 0 || std::size_t(v) >= nv)
                throw InvalidArgument("vertex_normals: triangle " + std::to_string(k) + " names vertex " +
                                      std::to_string(v) + ", outside 0.." + std::to_string(nv) + " - 1");
        double ab[3], ac[3], c[3];
        sub(&positions[3 * std::size_t(t[1])], &positions[3 * std::size_t(t[0])], ab);
        sub(&positions[3 * std::size_t(t[2])], &positions[3 * std::size_t(t[0])], ac);
        cross(ab, ac, c);  // twice the area times the unit normal
        for (index_t v : t)
            for (int i = 0; i < 3; ++i) n[3 * std::size_t(v) + i] += c[i];
    }
    for (std::size_t v = 0; v < nv; ++v) {
        const double len = std::sqrt(dot(&n[3 * v], &n[3 * v]));
        if (len > 0)
            for (int i = 0; i < 3; ++i) n[3 * v + i] /= len;
    }
    return n;
}

template void embedded_positions<double>(const Mesh&, const Embedding&, std::span<const double>, std::span<double>);
template void embedded_positions<float>(const Mesh&, const Embedding&, std::span<const float>, std::span<double>);

}  // namespace edgefem
