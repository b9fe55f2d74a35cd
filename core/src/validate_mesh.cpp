// Mesh validation. Messages name the element with Mesh::describe_tet /
// describe_vertex, which carry the file and line, so the MeshError itself is
// built without a "file:line:" prefix (that would say it twice); it still
// records the element index.
#include "edgefem/core/validate_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {

std::string num(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", x);
    return buffer;
}

const double* vertex(const Mesh& m, index_t v) { return &m.X[3 * static_cast<std::size_t>(v)]; }

// Vertex v as the file numbers it (a message quoting a tet's vertices must
// match what the user sees in the file: TetGen may start at 1, Gmsh tags).
std::string file_vertex(const Mesh& m, index_t v) {
    const auto& id = m.source.vertex_id;
    return std::to_string(static_cast<std::size_t>(v) < id.size() ? id[v] : v);
}

void check_structure(const Mesh& mesh) {
    const auto& src = mesh.source;
    if (mesh.X.size() % 3 != 0)
        throw MeshError("mesh has " + std::to_string(mesh.X.size()) +
                            " coordinates, not a multiple of 3",
                        src.vertex_file);
    if (mesh.tets.size() % 4 != 0)
        throw MeshError("mesh has " + std::to_string(mesh.tets.size()) +
                            " tet indices, not a multiple of 4",
                        src.tet_file);
    if (mesh.num_tets() == 0) throw MeshError("mesh has no tets", src.tet_file);
    if (!mesh.region.empty() && mesh.region.size() != mesh.tets.size() / 4)
        throw MeshError("mesh has " + std::to_string(mesh.region.size()) + " region ids for " +
                            std::to_string(mesh.num_tets()) + " tets",
                        src.tet_file);
    const TaggedTriangles& tri = mesh.surfaces;
    if (tri.vertices.size() != 3 * tri.tag.size())
        throw MeshError("mesh has " + std::to_string(tri.vertices.size()) + " tagged-triangle indices for " +
                            std::to_string(tri.tag.size()) + " tags (expected 3 per triangle)",
                        src.triangle_file);
}

// The tagged triangles' indices: in range, three distinct vertices.
void check_triangle_indices(const Mesh& mesh) {
    const index_t nv = mesh.num_vertices();
    const TaggedTriangles& tri = mesh.surfaces;
    for (std::size_t k = 0; k < tri.size(); ++k) {
        const index_t* v = &tri.vertices[3 * k];
        for (int i = 0; i < 3; ++i) {
            if (v[i] < 0 || v[i] >= nv)
                throw MeshError(mesh.describe_triangle(k) + ": vertex index " + std::to_string(v[i]) +
                                    " is out of range (the mesh has " + std::to_string(nv) + " vertices)",
                                {}, 0, static_cast<std::int64_t>(k));
            for (int j = 0; j < i; ++j)
                if (v[j] == v[i])
                    throw MeshError(mesh.describe_triangle(k) + " is degenerate: it uses vertex " +
                                        file_vertex(mesh, v[i]) + " twice",
                                    {}, 0, static_cast<std::int64_t>(k));
        }
    }
}

void check_indices(const Mesh& mesh) {
    const index_t nv = mesh.num_vertices(), nt = mesh.num_tets();
    for (index_t t = 0; t < nt; ++t) {
        const index_t* tet = &mesh.tets[4 * static_cast<std::size_t>(t)];
        for (int k = 0; k < 4; ++k) {
            if (tet[k] < 0 || tet[k] >= nv)
                throw MeshError(mesh.describe_tet(t) + ": vertex index " + std::to_string(tet[k]) +
                                    " is out of range (the mesh has " + std::to_string(nv) +
                                    " vertices)",
                                {}, 0, t);
            for (int j = 0; j < k; ++j)
                if (tet[j] == tet[k])
                    throw MeshError(mesh.describe_tet(t) + " is degenerate: it uses vertex " +
                                        file_vertex(mesh, tet[k]) + " twice",
                                    {}, 0, t);
        }
    }
}

void check_finite(const Mesh& mesh) {
    for (index_t v = 0; v < mesh.num_vertices(); ++v) {
        const double* p = vertex(mesh, v);
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            throw MeshError(mesh.describe_vertex(v) + " has a non-finite coordinate (" + num(p[0]) +
                                ", " + num(p[1]) + ", " + num(p[2]) + ")",
                            {}, 0, v);
    }
}

// Normalised volume 6 sqrt(2) |vol| / lmax^3: 1 for a regular tet, 0 when flat.
double normalised_volume(const double* p[4], double volume, double* lmax_out) {
    double l2 = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            const double dx = p[j][0] - p[i][0], dy = p[j][1] - p[i][1], dz = p[j][2] - p[i][2];
            l2 = std::max(l2, dx * dx + dy * dy + dz * dz);
        }
    const double lmax = std::sqrt(l2);
    *lmax_out = lmax;
    return lmax > 0 ? 6.0 * std::sqrt(2.0) * std::fabs(volume) / (l2 * lmax) : 0.0;
}

// Finds two tets with the same vertex set by sorting the sorted quadruples.
void check_duplicates(const Mesh& mesh) {
    struct Key {
        std::array<index_t, 4> v;
        index_t t;
    };
    const index_t nt = mesh.num_tets();
    std::vector<Key> keys(nt);
    for (index_t t = 0; t < nt; ++t) {
        Key& k = keys[t];
        std::copy_n(&mesh.tets[4 * static_cast<std::size_t>(t)], 4, k.v.begin());
        std::sort(k.v.begin(), k.v.end());
        k.t = t;
    }
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
        return a.v != b.v ? a.v < b.v : a.t < b.t;
    });
    index_t count = 0, first_a = -1, first_b = -1;
    for (index_t i = 1; i < nt; ++i)
        if (keys[i].v == keys[i - 1].v) {
            ++count;
            // Report the pair whose later tet comes first in the file.
            if (first_b < 0 || keys[i].t < first_b) {
                first_a = keys[i - 1].t;
                first_b = keys[i].t;
            }
        }
    if (count == 0) return;
    const index_t* tet = &mesh.tets[4 * static_cast<std::size_t>(first_b)];
    std::string msg = mesh.describe_tet(first_b) + " duplicates " + mesh.describe_tet(first_a) +
                      " (same vertices " + file_vertex(mesh, tet[0]) + " " + file_vertex(mesh, tet[1]) +
                      " " + file_vertex(mesh, tet[2]) + " " + file_vertex(mesh, tet[3]) + ")";
    if (count > 1) msg += "; " + std::to_string(count) + " duplicate tets in all";
    throw MeshError(msg, {}, 0, first_b);
}

void handle_unreferenced(Mesh& mesh, const ValidationOptions& options, ValidationReport& report) {
    const index_t nv = mesh.num_vertices();
    std::vector<index_t> renumber(nv, -1);
    for (const index_t v : mesh.tets) renumber[v] = 0;
    index_t unused = 0, first = -1;
    for (index_t v = 0; v < nv; ++v)
        if (renumber[v] < 0) {
            if (first < 0) first = v;
            ++unused;
        }
    report.unreferenced_vertices = unused;
    if (unused == 0) return;
    if (!options.compact_unreferenced) {
        report.warnings.push_back(std::to_string(unused) + " of " + std::to_string(nv) +
                                  " vertices are not used by any tet (the first is " +
                                  mesh.describe_vertex(first) +
                                  "); to remove them, " + options.compact_hint);
        return;
    }
    report.warnings.push_back("removed " + std::to_string(unused) +
                              " vertices not used by any tet (the first was " +
                              mesh.describe_vertex(first) + ")");
    auto& src = mesh.source;
    const bool lines = src.vertex_line.size() == static_cast<std::size_t>(nv);
    const bool ids = src.vertex_id.size() == static_cast<std::size_t>(nv);
    index_t next = 0;
    for (index_t v = 0; v < nv; ++v) {
        if (renumber[v] < 0) continue;
        renumber[v] = next;
        std::copy_n(&mesh.X[3 * static_cast<std::size_t>(v)], 3,
                    &mesh.X[3 * static_cast<std::size_t>(next)]);
        if (lines) src.vertex_line[next] = src.vertex_line[v];
        if (ids) src.vertex_id[next] = src.vertex_id[v];
        ++next;
    }
    mesh.X.resize(3 * static_cast<std::size_t>(next));
    if (lines) src.vertex_line.resize(next);
    if (ids) src.vertex_id.resize(next);
    for (index_t& v : mesh.tets) v = renumber[v];
    report.removed_vertices = unused;
    // Tagged triangles follow; one that uses a removed vertex bounds no tet
    // and is dropped.
    TaggedTriangles& tri = mesh.surfaces;
    const bool tri_lines = src.triangle_line.size() == tri.size();
    std::size_t kept = 0, dropped = 0;
    std::string first_dropped;
    for (std::size_t k = 0; k < tri.size(); ++k) {
        const index_t* v = &tri.vertices[3 * k];
        if (renumber[v[0]] < 0 || renumber[v[1]] < 0 || renumber[v[2]] < 0) {
            if (dropped++ == 0) first_dropped = mesh.describe_triangle(k);
            continue;
        }
        for (int i = 0; i < 3; ++i) tri.vertices[3 * kept + i] = renumber[v[i]];
        tri.tag[kept] = tri.tag[k];
        if (tri_lines) src.triangle_line[kept] = src.triangle_line[k];
        ++kept;
    }
    if (dropped > 0)
        report.warnings.push_back("dropped " + std::to_string(dropped) +
                                  " tagged triangles that use a removed vertex (the first is " +
                                  first_dropped + ")");
    tri.vertices.resize(3 * kept);
    tri.tag.resize(kept);
    if (tri_lines) src.triangle_line.resize(kept);
}

// Every check that needs no change to the mesh; returns the negatively
// oriented tets (not an error here: validate_mesh may flip them).
std::vector<index_t> check_all_but_orientation(const Mesh& mesh, const ValidationOptions& options) {
    check_structure(mesh);
    check_indices(mesh);
    check_triangle_indices(mesh);
    check_finite(mesh);

    // One pass for degenerate and inverted tets; degenerate ones are reported
    // first, as no orientation can be given to a flat tet.
    const index_t nt = mesh.num_tets();
    std::vector<index_t> inverted;
    index_t degenerate = 0, first_degenerate = -1;
    double first_q = 0, first_volume = 0, first_lmax = 0;
    for (index_t t = 0; t < nt; ++t) {
        const index_t* tet = &mesh.tets[4 * static_cast<std::size_t>(t)];
        const double* p[4] = {vertex(mesh, tet[0]), vertex(mesh, tet[1]), vertex(mesh, tet[2]),
                              vertex(mesh, tet[3])};
        const double volume = signed_volume(p[0], p[1], p[2], p[3]);
        double lmax = 0;
        const double q = normalised_volume(p, volume, &lmax);
        if (!(q >= options.degenerate_tolerance)) {
            if (degenerate++ == 0) {
                first_degenerate = t;
                first_q = q;
                first_volume = volume;
                first_lmax = lmax;
            }
        } else if (volume < 0) {
            inverted.push_back(t);
        }
    }
    if (degenerate > 0) {
        std::string msg = mesh.describe_tet(first_degenerate) +
                          " is degenerate: its normalised volume " + num(first_q) +
                          " is below the tolerance " + num(options.degenerate_tolerance) +
                          " (volume " + num(first_volume) + ", longest edge " + num(first_lmax) +
                          ")";
        if (degenerate > 1) msg += "; " + std::to_string(degenerate) + " degenerate tets in all";
        throw MeshError(msg, {}, 0, first_degenerate);
    }

    check_duplicates(mesh);
    return inverted;
}

[[noreturn]] void throw_inverted(const Mesh& mesh, const std::vector<index_t>& inverted,
                                 const ValidationOptions& options) {
    throw MeshError(std::to_string(inverted.size()) + " of " + std::to_string(mesh.num_tets()) +
                        " tets are inverted (negative volume); the first is " + mesh.describe_tet(inverted.front()) +
                        ". To flip them, " + options.fix_orientation_hint,
                    {}, 0, inverted.front());
}

}  // namespace

ValidationReport validate_mesh(Mesh& mesh, const ValidationOptions& options) {
    const std::vector<index_t> inverted = check_all_but_orientation(mesh, options);
    ValidationReport report;
    if (!inverted.empty()) {
        if (!options.fix_orientation) throw_inverted(mesh, inverted, options);
        for (const index_t t : inverted)
            std::swap(mesh.tets[4 * static_cast<std::size_t>(t) + 2],
                      mesh.tets[4 * static_cast<std::size_t>(t) + 3]);
        report.flipped_tets = static_cast<index_t>(inverted.size());
        report.warnings.push_back("flipped " + std::to_string(inverted.size()) +
                                  " inverted tets (the first is " +
                                  mesh.describe_tet(inverted.front()) + ")");
    }
    handle_unreferenced(mesh, options, report);
    return report;
}

void check_mesh_indices(const Mesh& mesh) {
    check_structure(mesh);
    check_indices(mesh);
}

void check_mesh(const Mesh& mesh, const ValidationOptions& options) {
    const std::vector<index_t> inverted = check_all_but_orientation(mesh, options);
    if (!inverted.empty()) throw_inverted(mesh, inverted, options);
}

}  // namespace edgefem
