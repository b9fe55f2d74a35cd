#include "edgefem/core/surface_selection.hpp"

#include <algorithm>
#include <cstdint>
#include <set>
#include <string>
#include <type_traits>
#include <unordered_map>

#include "edgefem/core/error.hpp"
#include "edgefem/core/surface.hpp"

namespace edgefem {

namespace {

// "3, 7 and 9" (at most 20 listed).
template <class T>
std::string list(const std::set<T>& items, const char* quote = "") {
    std::string out;
    std::size_t k = 0;
    for (const T& x : items) {
        if (k == 20) return out + ", ... (" + std::to_string(items.size()) + " in all)";
        std::string s;
        if constexpr (std::is_same_v<T, std::string>) s = printable(x);
        else s = std::to_string(x);
        out += (k == 0 ? "" : k + 1 == items.size() ? " and " : ", ") + std::string(quote) + s + quote;
        ++k;
    }
    return out;
}

std::string what_the_mesh_has(const Mesh& mesh) {
    if (mesh.surfaces.size() == 0)
        return "the mesh has no tagged triangles (Gmsh physical surfaces, a TetGen .face file with boundary markers, "
               "MEDIT Triangles)";
    const std::set<int> tags(mesh.surfaces.tag.begin(), mesh.surfaces.tag.end());
    return "the mesh's triangles have tag" + std::string(tags.size() == 1 ? " " : "s ") + list(tags);
}

std::array<index_t, 3> sorted(const Triangle& t) {
    std::array<index_t, 3> s = t;
    std::sort(s.begin(), s.end());
    return s;
}

struct TriangleHash {
    std::size_t operator()(const std::array<index_t, 3>& t) const {
        std::size_t h = std::size_t(std::uint32_t(t[0]));
        h = h * 0x9E3779B97F4A7C15ull + std::size_t(std::uint32_t(t[1]));
        return h * 0x9E3779B97F4A7C15ull + std::size_t(std::uint32_t(t[2]));
    }
};

}  // namespace

std::vector<Triangle> tagged_triangles(const Mesh& mesh, const std::vector<int>& tags) {
    const TaggedTriangles& s = mesh.surfaces;
    const std::set<int> want(tags.begin(), tags.end());
    std::set<int> found;
    std::vector<Triangle> out;
    for (std::size_t k = 0; k < s.size(); ++k)
        if (want.count(s.tag[k])) {
            found.insert(s.tag[k]);
            out.push_back({s.vertices[3 * k], s.vertices[3 * k + 1], s.vertices[3 * k + 2]});
        }
    for (const int t : tags)
        if (!found.count(t))
            throw InvalidArgument("no triangle has surface tag " + std::to_string(t) + " (" + what_the_mesh_has(mesh) + ")");
    return out;
}

std::vector<int> tags_named(const Mesh& mesh, const std::string& name) {
    std::vector<int> out;
    std::set<std::string> names;
    for (const auto& [tag, n] : mesh.surfaces.names) {
        names.insert(n);
        if (n == name) out.push_back(tag);
    }
    if (out.empty())
        throw InvalidArgument("no physical surface is named \"" + printable(name) + "\" (" +
                              (names.empty() ? std::string("the mesh names none: physical names come from a Gmsh "
                                                           "file's $PhysicalNames of dimension 2")
                                             : "the mesh's are " + list(names, "\"")) +
                              ")");
    return out;
}

std::vector<Triangle> orient_outward(const Mesh& mesh, const std::vector<Triangle>& triangles) {
    const BoundarySurface b = boundary_surface(mesh);
    std::unordered_map<std::array<index_t, 3>, std::size_t, TriangleHash> face;
    face.reserve(b.triangles.size());
    for (std::size_t k = 0; k < b.triangles.size(); ++k) face.emplace(sorted(b.triangles[k]), k);
    std::vector<Triangle> out;
    out.reserve(triangles.size());
    for (const Triangle& t : triangles) {
        const auto it = face.find(sorted(t));
        if (it == face.end()) {
            const auto id = [&](index_t v) {
                const auto& ids = mesh.source.vertex_id;
                return std::to_string(std::size_t(v) < ids.size() ? ids[v] : v);
            };
            throw MeshError("the triangle of vertices " + id(t[0]) + " " + id(t[1]) + " " + id(t[2]) +
                            " (as the mesh file numbers them) is not on the boundary (it bounds no tet, or two): a "
                            "surface load needs an outside");
        }
        out.push_back(b.triangles[it->second]);
    }
    return out;
}

std::vector<Triangle> boundary_in_box(const Mesh& mesh, const std::array<double, 3>& lo,
                                      const std::array<double, 3>& hi) {
    const auto inside = [&](index_t v) {
        for (int c = 0; c < 3; ++c) {
            const double x = mesh.X[3 * std::size_t(v) + c];
            if (!(x >= lo[c] && x <= hi[c])) return false;
        }
        return true;
    };
    std::vector<Triangle> out;
    for (const Triangle& t : boundary_surface(mesh).triangles)
        if (inside(t[0]) && inside(t[1]) && inside(t[2])) out.push_back(t);
    return out;
}

std::vector<index_t> triangle_vertices(const std::vector<Triangle>& triangles) {
    std::vector<index_t> out;
    out.reserve(3 * triangles.size());
    for (const Triangle& t : triangles) out.insert(out.end(), t.begin(), t.end());
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

}  // namespace edgefem
