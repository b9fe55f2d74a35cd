// TetGen .node/.ele reader. Numbering starts at 0 or 1, as the first vertex
// number in the .node file says (TetGen's own rule); the .ele file's vertex
// indices use that base. Lines must hold exactly the values their header
// declares, so a wrong header is caught instead of misread.
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "text_reader.hpp"

namespace edgefem {

namespace {

// Whether `s` ends with `suffix`, ignoring ASCII case (read_mesh detects the
// format that way, so OK.NODE must read too).
bool iends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           detail::iequals(std::string_view(s).substr(s.size() - suffix.size()), suffix);
}

// prefix + ext ("ele"): upper-case when the file we were given is (OK.NODE
// goes with OK.ELE), unless only the other case exists.
std::string partner(const std::string& prefix, const std::string& ext, bool upper) {
    const std::string preferred = prefix + "." + (upper ? detail::ascii_upper(ext) : ext);
    const std::string other = prefix + "." + (upper ? ext : detail::ascii_upper(ext));
    std::error_code ec;
    if (!std::filesystem::exists(preferred, ec) && std::filesystem::exists(other, ec)) return other;
    return preferred;
}

// The .node and .ele files of `path`: either file or their common prefix.
std::pair<std::string, std::string> tetgen_files(const std::string& path) {
    const auto upper = [&](std::size_t n) {
        const std::string ext = path.substr(path.size() - n);
        return ext == detail::ascii_upper(ext);
    };
    if (iends_with(path, ".node")) {
        const std::string prefix = path.substr(0, path.size() - 5);
        return {path, partner(prefix, "ele", upper(4))};
    }
    if (iends_with(path, ".ele")) {
        const std::string prefix = path.substr(0, path.size() - 4);
        return {partner(prefix, "node", upper(3)), path};
    }
    const std::string node = partner(path, "node", false);
    return {node, partner(path, "ele", node.back() == 'E')};
}

// Checks an item number: the first sets the base (0 or 1), the others must
// follow it consecutively; a repeated number is reported as a duplicate.
std::int64_t check_number(const detail::TextReader& r, std::int64_t id, std::int64_t i,
                          std::int64_t base, const std::vector<std::int64_t>& lines,
                          const char* kind) {
    if (i == 0) {
        if (id != 0 && id != 1)
            r.fail(std::string("the first ") + kind + " must be numbered 0 or 1, got " +
                   std::to_string(id));
        return id;
    }
    if (id == base + i) return base;
    if (id >= base && id < base + i)
        r.fail(std::string("duplicate ") + kind + " number " + std::to_string(id) +
               " (first defined at line " + std::to_string(lines[id - base]) + ")");
    r.fail(std::string(kind) + "s must be numbered consecutively: expected " +
           std::to_string(base + i) + ", got " + std::to_string(id));
}

// Reads the .node file into mesh.X; returns the numbering base.
std::int64_t read_node_file(const std::string& file, Mesh& mesh) {
    detail::TextReader r(file, '#');
    r.require_line("the header line 'N 3 #attributes #markers'");
    auto header = r.tokens();
    const std::int64_t n = r.next_int(header, "vertex count in the header");
    const std::int64_t dim = header.empty() ? 3 : r.next_int(header, "dimension");
    const std::int64_t nattr = header.empty() ? 0 : r.next_int(header, "attribute count");
    const std::int64_t nmark = header.empty() ? 0 : r.next_int(header, "boundary marker flag");
    r.expect_end(header, "the header 'N 3 #attributes #markers'");
    if (dim != 3) r.fail("dimension must be 3, got " + std::to_string(dim));
    if (nattr < 0 || nattr > 1000)
        r.fail("bad attribute count " + std::to_string(nattr) + " in the header");
    if (nmark != 0 && nmark != 1)
        r.fail("boundary marker flag must be 0 or 1, got " + std::to_string(nmark));
    const index_t nv = r.check_count(n, static_cast<int>(4 + nattr + nmark), "vertex");

    // Grown line by line, never sized from the header's count: a count the
    // file does not back costs nothing before the short line is found.
    auto& src = mesh.source;
    src.vertex_file = file;
    std::int64_t base = 0;
    for (index_t v = 0; v < nv; ++v) {
        r.require_line("vertex " + std::to_string(v + 1) + " of " + std::to_string(nv));
        auto tk = r.tokens();
        const std::int64_t id = r.next_int(tk, "vertex number");
        base = check_number(r, id, v, base, src.vertex_line, "vertex");
        double p[3];
        p[0] = r.next_double(tk, "x coordinate");
        p[1] = r.next_double(tk, "y coordinate");
        p[2] = r.next_double(tk, "z coordinate");
        for (std::int64_t a = 0; a < nattr; ++a) r.next_double(tk, "vertex attribute");
        if (nmark) r.next_int(tk, "boundary marker");
        r.expect_end(tk, "the values the header declares for vertex " + std::to_string(id));
        detail::check_finite(r, p, v, id);
        mesh.X.insert(mesh.X.end(), p, p + 3);
        src.vertex_line.push_back(r.line_no());
        src.vertex_id.push_back(id);
    }
    if (r.next_line())
        r.fail("more vertex lines than the header's count " + std::to_string(nv));
    return base;
}

// Returns whether the tets are second order (10 nodes).
bool read_ele_file(const std::string& file, std::int64_t base, Mesh& mesh, ReadReport* report) {
    detail::TextReader r(file, '#');
    r.require_line("the header line 'T 4 #attributes'");
    auto header = r.tokens();
    const std::int64_t n = r.next_int(header, "tet count in the header");
    const std::int64_t npt = header.empty() ? 4 : r.next_int(header, "nodes per tet");
    const std::int64_t nattr = header.empty() ? 0 : r.next_int(header, "attribute count");
    r.expect_end(header, "the header 'T 4 #attributes'");
    if (npt != 4 && npt != 10)
        r.fail("nodes per tet must be 4 or 10, got " + std::to_string(npt));
    if (nattr < 0 || nattr > 1000)
        r.fail("bad attribute count " + std::to_string(nattr) + " in the header");
    const index_t nt = r.check_count(n, static_cast<int>(1 + npt + nattr), "tet");

    auto& src = mesh.source;
    src.tet_file = file;
    std::vector<std::int64_t> raw;  // grown line by line, as the vertices
    std::int64_t tet_base = 0;
    for (index_t t = 0; t < nt; ++t) {
        r.require_line("tet " + std::to_string(t + 1) + " of " + std::to_string(nt));
        auto tk = r.tokens();
        const std::int64_t id = r.next_int(tk, "tet number");
        tet_base = check_number(r, id, t, tet_base, src.tet_line, "tet");
        src.tet_line.push_back(r.line_no());
        src.tet_id.push_back(id);
        for (std::int64_t k = 0; k < npt; ++k) {
            const std::int64_t v = r.next_int(tk, "vertex index");
            if (k < 4) raw.push_back(v);
            // Mid-edge nodes are range-checked here, as they are not kept.
            if (k >= 4 && (v < base || v - base >= mesh.num_vertices()))
                r.fail(detail::item_label("tet", t, id) + ": vertex index " + std::to_string(v) +
                           " is out of range",
                       t);
        }
        for (std::int64_t a = 0; a < nattr; ++a) {
            const double value = r.next_double(tk, "tet attribute");
            if (a == 0) mesh.region.push_back(detail::region_from_attribute(r, value));
        }
        r.expect_end(tk, "the values the header declares for tet " + std::to_string(id));
    }
    if (r.next_line()) r.fail("more tet lines than the header's count " + std::to_string(nt));
    mesh.tets = detail::resolve_tets(file, raw, base, mesh.num_vertices(), src.tet_line, src.tet_id);
    if (npt == 10 && report) report->high_order_tets = true;
    if (npt == 10 && report)
        report->warnings.push_back(
            file + ": 10-node tets: kept the 4 corner nodes; the mid-edge nodes are left "
                   "unreferenced (validate_mesh with compact_unreferenced removes them)");
    return npt == 10;
}

// The optional .face file: 'F #markers' then 'id a b c [marker]' lines (6
// nodes for second-order meshes; two trailing adjacent-tet numbers, as
// tetgen -nn writes them, are accepted). With boundary markers the faces
// become the mesh's tagged triangles; without, they carry no tag and are
// not kept.
void read_face_file(const std::string& file, std::int64_t base, bool second_order, Mesh& mesh) {
    detail::TextReader r(file, '#');
    r.require_line("the header line 'F #markers'");
    auto header = r.tokens();
    const std::int64_t n = r.next_int(header, "face count in the header");
    const std::int64_t nmark = header.empty() ? 0 : r.next_int(header, "boundary marker flag");
    r.expect_end(header, "the header 'F #markers'");
    if (nmark != 0 && nmark != 1) r.fail("boundary marker flag must be 0 or 1, got " + std::to_string(nmark));
    const int nodes = second_order ? 6 : 3;
    const index_t nf = r.check_count(n, 1 + nodes + int(nmark), "face");
    std::vector<std::int64_t> raw, lines, ids;
    std::vector<int> tags;
    std::int64_t face_base = 0;
    for (index_t f = 0; f < nf; ++f) {
        r.require_line("face " + std::to_string(f + 1) + " of " + std::to_string(nf));
        auto tk = r.tokens();
        const std::int64_t id = r.next_int(tk, "face number");
        face_base = check_number(r, id, f, face_base, lines, "face");
        for (int k = 0; k < nodes; ++k) {
            const std::int64_t v = r.next_int(tk, "vertex index");
            if (k < 3) raw.push_back(v);
            if (k >= 3 && (v < base || v - base >= mesh.num_vertices()))
                r.fail(detail::item_label("face", f, id) + ": vertex index " + std::to_string(v) + " is out of range", f);
        }
        std::int64_t marker = 0;
        if (nmark) marker = r.next_int(tk, "boundary marker");
        if (tk.count() == 2) {  // tetgen -nn: the two adjacent tets
            r.next_int(tk, "adjacent tet");
            r.next_int(tk, "adjacent tet");
        }
        r.expect_end(tk, "the values the header declares for face " + std::to_string(id));
        if (marker < std::numeric_limits<int>::min() || marker > std::numeric_limits<int>::max())
            r.fail("boundary marker " + std::to_string(marker) + " does not fit an int");
        lines.push_back(r.line_no());
        ids.push_back(id);
        tags.push_back(static_cast<int>(marker));
    }
    if (r.next_line()) r.fail("more face lines than the header's count " + std::to_string(nf));
    const std::vector<index_t> tri = detail::resolve_indices(file, raw, 3, "face", base, mesh.num_vertices(), lines, ids);
    if (!nmark) return;
    mesh.surfaces.vertices = tri;
    mesh.surfaces.tag = std::move(tags);
    mesh.source.triangle_file = file;
    mesh.source.triangle_line = std::move(lines);
}

}  // namespace

Mesh read_tetgen(const std::string& path, ReadReport* report) {
    const auto [node, ele] = tetgen_files(path);
    Mesh mesh;
    const std::int64_t base = read_node_file(node, mesh);
    const bool second_order = read_ele_file(ele, base, mesh, report);
    // The .face file next to the .node file, when there is one.
    const std::string prefix = node.substr(0, node.size() - 5);
    const std::string face = partner(prefix, "face", node.back() == 'E');
    std::error_code ec;
    if (iends_with(node, ".node") && std::filesystem::is_regular_file(face, ec))
        read_face_file(face, base, second_order, mesh);
    return mesh;
}

}  // namespace edgefem
