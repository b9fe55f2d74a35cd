// MEDIT .mesh (ASCII) reader. Keywords are case-insensitive and a keyword's
// value may sit on its own line; the items of a section are one per line,
// as every MEDIT writer puts them. Tetrahedra are read, and TetrahedraP2
// keep their 4 corners (MEDIT lists the corners first). Other volume
// sections (Hexahedra, Prisms, ...) are an error: simulating the tets alone
// would drop part of the body. The remaining sections are skipped (one line
// per item) and counted.
#include <limits>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "text_reader.hpp"

namespace edgefem {

namespace {

// Keyword stream: tokens across lines, as MEDIT allows "Dimension\n3".
class Words {
public:
    explicit Words(detail::TextReader& r) : r_(r), tokens_("") {}
    // The next token, or empty at the end of the file.
    std::string_view next() {
        for (;;) {
            const std::string_view t = tokens_.next();
            if (!t.empty()) return t;
            if (!r_.next_line()) return {};
            tokens_ = r_.tokens();
        }
    }
    std::int64_t next_int(const std::string& what) {
        const std::string_view t = next();
        if (t.empty()) r_.fail("unexpected end of file (truncated?): expected " + what);
        return r_.parse_int(t, what);
    }
    // Item lines follow; the current line must have nothing left.
    void end_of_header(const std::string& what) {
        r_.expect_end(tokens_, what);
        tokens_ = detail::LineTokens("");
    }

private:
    detail::TextReader& r_;
    detail::LineTokens tokens_;
};

// Point, line and surface element sections: boundary markup, skipped.
bool is_element_section(const std::string& kw) {
    static const std::set<std::string> kinds = {"edges", "triangles", "quadrilaterals", "edgesp2",
                                                "trianglesp2", "quadrilateralsq2"};
    return kinds.count(kw) > 0;
}

// Volume element sections that are not read.
bool is_volume_section(const std::string& kw) {
    static const std::set<std::string> kinds = {
        "hexahedra",    "prisms",       "pyramids",     "hexahedraq2", "hexahedraq3",
        "hexahedraq4",  "prismsp2",     "prismsp3",     "prismsp4",    "pyramidsp2",
        "pyramidsp3",   "pyramidsp4",   "tetrahedrap3", "tetrahedrap4"};
    return kinds.count(kw) > 0;
}

// Tets as read: 4 corner indices each, numbered from 1, resolved at the end.
struct TetSections {
    bool have_tets = false, have_p2 = false;
    std::vector<std::int64_t> raw;
    std::vector<std::pair<std::int64_t, index_t>> mid;  // TetrahedraP2: (mid-edge index, tet)
};

// One Tetrahedra (nodes = 4) or TetrahedraP2 (nodes = 10) section: item
// lines of `nodes` vertex indices and an optional reference.
void read_tets(detail::TextReader& r, Words& words, int nodes, Mesh& mesh, TetSections& tets) {
    auto& src = mesh.source;
    const index_t n = r.check_count(words.next_int("the tet count"), nodes, "tet");
    words.end_of_header("the tet count");
    const auto first = static_cast<index_t>(tets.raw.size() / 4);
    if (std::int64_t{first} + n > std::numeric_limits<index_t>::max())
        r.fail("the tet sections hold more than 2^31-1 tets");
    // Grown line by line, never sized from the count (a count the file does
    // not back costs nothing).
    for (index_t i = 0; i < n; ++i) {
        const index_t t = first + i;
        r.require_line("tet " + std::to_string(i + 1) + " of " + std::to_string(n));
        auto tk = r.tokens();
        for (int k = 0; k < 4; ++k) tets.raw.push_back(r.next_int(tk, "vertex index"));
        for (int k = 4; k < nodes; ++k) tets.mid.emplace_back(r.next_int(tk, "vertex index"), t);
        std::int64_t ref = 0;
        if (!tk.empty()) ref = r.next_int(tk, "tet reference");
        r.expect_end(tk, "tet " + std::to_string(i + 1));
        if (ref < std::numeric_limits<int>::min() || ref > std::numeric_limits<int>::max())
            r.fail("tet reference " + std::to_string(ref) + " does not fit an int");
        mesh.region.push_back(static_cast<int>(ref));
        src.tet_line.push_back(r.line_no());
        src.tet_id.push_back(i + 1);  // numbered within its section
    }
}

// Moves to item line i of a section of `count` (`verb`: "skipping" or
// "reading"). An item line starts with a number, so a keyword where an item
// should be means the count is too large.
void require_item(detail::TextReader& r, const char* verb, const std::string& name, index_t count, index_t i) {
    r.require_line("item " + std::to_string(i + 1) + " of section " + name);
    const char c = r.line().front();
    if (!(c == '-' || c == '+' || c == '.' || (c >= '0' && c <= '9')))
        r.fail(std::string("while ") + verb + " section " + name + " (" + std::to_string(count) + " items): expected item " +
               std::to_string(i + 1) + ", found keyword '" + detail::quote(r.tokens().next()) + "'");
}

void skip_items(detail::TextReader& r, const std::string& name, index_t count) {
    for (index_t i = 0; i < count; ++i) require_item(r, "skipping", name, count, i);
}

// A Triangles section: item lines 'a b c [reference]' (1-based), kept as
// the mesh's tagged triangles (resolved at the end, as the tets).
void read_triangles(detail::TextReader& r, Words& words, const std::string& name, std::vector<std::int64_t>& raw,
                    Mesh& mesh) {
    const index_t n = r.check_count(words.next_int("the triangle count"), 3, "triangle");
    words.end_of_header("the triangle count");
    if (std::int64_t(mesh.surfaces.size()) + n > std::numeric_limits<index_t>::max())
        r.fail("the Triangles sections hold more than 2^31-1 triangles");
    for (index_t i = 0; i < n; ++i) {
        require_item(r, "reading", name, n, i);
        auto tk = r.tokens();
        for (int k = 0; k < 3; ++k) raw.push_back(r.next_int(tk, "vertex index"));
        std::int64_t ref = 0;
        if (!tk.empty()) ref = r.next_int(tk, "triangle reference");
        r.expect_end(tk, "triangle " + std::to_string(i + 1));
        if (ref < std::numeric_limits<int>::min() || ref > std::numeric_limits<int>::max())
            r.fail("triangle reference " + std::to_string(ref) + " does not fit an int");
        mesh.surfaces.tag.push_back(static_cast<int>(ref));
        mesh.source.triangle_line.push_back(r.line_no());
    }
}


// A section keyword starts with a letter; a number there means the previous
// section has more items than its count.
void check_keyword(const detail::TextReader& r, std::string_view word, const std::string& previous) {
    const char c = word.front();
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')) return;
    std::string message = "expected a section keyword, got '" + detail::quote(word) + "'";
    if (!previous.empty()) message += " (does section " + previous + " have more items than its count?)";
    r.fail(message);
}

void read_vertices(detail::TextReader& r, Words& words, Mesh& mesh) {
    auto& src = mesh.source;
    const index_t n = r.check_count(words.next_int("the vertex count"), 3, "vertex");
    words.end_of_header("the vertex count");
    for (index_t v = 0; v < n; ++v) {
        r.require_line("vertex " + std::to_string(v + 1) + " of " + std::to_string(n));
        auto tk = r.tokens();
        double p[3];
        p[0] = r.next_double(tk, "x coordinate");
        p[1] = r.next_double(tk, "y coordinate");
        p[2] = r.next_double(tk, "z coordinate");
        if (!tk.empty()) r.next_int(tk, "vertex reference");
        r.expect_end(tk, "vertex " + std::to_string(v + 1));
        detail::check_finite(r, p, v, v + 1);
        mesh.X.insert(mesh.X.end(), p, p + 3);
        src.vertex_line.push_back(r.line_no());
        src.vertex_id.push_back(v + 1);
    }
}

// "2 x Corners, 1 x Edges".
std::string summary(const std::map<std::string, std::int64_t>& counts) {
    std::string out;
    for (const auto& [name, count] : counts)
        out += (out.empty() ? "" : ", ") + std::to_string(count) + " x " + name;
    return out;
}

}  // namespace

Mesh read_medit(const std::string& path, ReadReport* report) {
    detail::TextReader r(path, '#');
    Words words(r);
    Mesh mesh;
    auto& src = mesh.source;
    src.vertex_file = src.tet_file = path;

    const std::string_view first = words.next();
    if (first.empty()) r.fail(r.file_empty() ? "file is empty" : "no MeshVersionFormatted keyword");
    if (detail::iequals(first, "MeshVersionUnformatted"))
        r.fail("binary MEDIT files are not supported; save the mesh as ASCII");
    if (!detail::iequals(first, "MeshVersionFormatted"))
        r.fail("not a MEDIT file: expected 'MeshVersionFormatted', got '" + detail::quote(first) + "'");
    const std::int64_t version = words.next_int("the MeshVersionFormatted value");
    if (version < 1 || version > 4) r.fail("unsupported MEDIT version " + std::to_string(version));

    bool have_vertices = false;
    TetSections tets;
    std::map<std::string, std::int64_t> skipped, volume;
    std::int64_t first_volume_line = 0;
    std::string previous;  // the last section, for messages
    std::vector<std::int64_t> triangles;  // 3 vertex numbers per triangle, as read
    for (;;) {
        const std::string_view word = words.next();
        if (word.empty()) break;  // End is optional
        check_keyword(r, word, previous);
        const std::string kw = detail::ascii_lower(word);
        previous = detail::quote(word);
        if (kw == "end") break;
        if (kw == "dimension") {
            const std::int64_t dim = words.next_int("the dimension");
            if (dim != 3) r.fail("only 3-D meshes are supported, got dimension " + std::to_string(dim));
        } else if (kw == "vertices") {
            if (have_vertices) r.fail("a second Vertices section");
            have_vertices = true;
            read_vertices(r, words, mesh);
        } else if (kw == "tetrahedra" || kw == "tetrahedrap2") {
            bool& seen = kw == "tetrahedra" ? tets.have_tets : tets.have_p2;
            if (seen) r.fail("a second " + previous + " section");
            seen = true;
            read_tets(r, words, kw == "tetrahedra" ? 4 : 10, mesh, tets);
        } else if (kw == "triangles") {
            // Kept as tagged triangles; still counted with the elements not simulated.
            const std::size_t before = mesh.surfaces.size();
            read_triangles(r, words, previous, triangles, mesh);
            const auto n = static_cast<std::int64_t>(mesh.surfaces.size() - before);
            skipped[previous] += n;
            if (report) report->skipped_elements += n;
        } else {
            const std::int64_t line = r.line_no();
            const std::int64_t count = words.next_int("the item count of section '" + previous + "'");
            const index_t n = r.check_count(count, 1, "'" + previous + "' item");
            words.end_of_header("the item count");
            skip_items(r, previous, n);
            if (is_volume_section(kw)) {
                if (volume.empty()) first_volume_line = line;
                volume[previous] += n;
                continue;
            }
            skipped[previous] += n;
            if (report && is_element_section(kw)) report->skipped_elements += n;
        }
    }
    if (!volume.empty())
        r.fail_at(first_volume_line, "mesh has " + summary(volume) +
                                         ": edgefem simulates tets only; convert the mesh to tets");
    if (!have_vertices) r.fail("no Vertices section");
    if (!tets.have_tets && !tets.have_p2) r.fail("no Tetrahedra section");
    mesh.tets = detail::resolve_tets(path, tets.raw, 1, mesh.num_vertices(), src.tet_line, src.tet_id);
    if (!triangles.empty()) {
        src.triangle_file = path;
        mesh.surfaces.vertices =
            detail::resolve_indices(path, triangles, 3, "triangle", 1, mesh.num_vertices(), src.triangle_line, {});
    }
    for (const auto& [v, t] : tets.mid)
        if (v < 1 || v > mesh.num_vertices())
            r.fail_at(src.tet_line[t],
                      detail::item_label("tet", t, src.tet_id[t]) + ": vertex index " + std::to_string(v) +
                          " is out of range (vertices are numbered 1.." +
                          std::to_string(mesh.num_vertices()) + ")",
                      t);

    if (report) {
        if (!report->skipped_summary.empty() && !skipped.empty()) report->skipped_summary += ", ";
        report->skipped_summary += summary(skipped);
        report->high_order_tets = report->high_order_tets || tets.have_p2;
        if (tets.have_p2)
            report->warnings.push_back(
                path + ": TetrahedraP2: kept the 4 corner nodes; the mid-edge nodes are left "
                       "unreferenced (validate_mesh with compact_unreferenced removes them)");
    }
    return mesh;
}

}  // namespace edgefem
