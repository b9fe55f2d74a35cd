// MEDIT .mesh (ASCII) reader. Keywords are case-insensitive and a keyword's
// value may sit on its own line; the items of a section are one per line,
// as every MEDIT writer puts them. Sections other than Vertices and
// Tetrahedra are skipped (one line per item) and counted.
#include <limits>
#include <map>
#include <set>
#include <string>
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

bool is_element_section(const std::string& kw) {
    static const std::set<std::string> kinds = {
        "edges",      "triangles",  "quadrilaterals", "hexahedra",  "prisms",     "pyramids",
        "edgesp2",    "trianglesp2", "quadrilateralsq2", "tetrahedrap2", "hexahedraq2"};
    return kinds.count(kw) > 0;
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

    bool have_vertices = false, have_tets = false;
    std::vector<std::int64_t> raw;
    std::map<std::string, std::int64_t> skipped;
    for (;;) {
        const std::string_view word = words.next();
        if (word.empty()) break;  // End is optional
        const std::string kw = detail::ascii_lower(word);
        if (kw == "end") break;
        if (kw == "dimension") {
            const std::int64_t dim = words.next_int("the dimension");
            if (dim != 3) r.fail("only 3-D meshes are supported, got dimension " + std::to_string(dim));
        } else if (kw == "vertices") {
            if (have_vertices) r.fail("a second Vertices section");
            have_vertices = true;
            const index_t n = r.check_count(words.next_int("the vertex count"), 3, "vertex");
            words.end_of_header("the vertex count");
            mesh.X.resize(3 * static_cast<std::size_t>(n));
            src.vertex_line.resize(n);
            src.vertex_id.resize(n);
            for (index_t v = 0; v < n; ++v) {
                r.require_line("vertex " + std::to_string(v + 1) + " of " + std::to_string(n));
                auto tk = r.tokens();
                double* p = &mesh.X[3 * static_cast<std::size_t>(v)];
                p[0] = r.next_double(tk, "x coordinate");
                p[1] = r.next_double(tk, "y coordinate");
                p[2] = r.next_double(tk, "z coordinate");
                if (!tk.empty()) r.next_int(tk, "vertex reference");
                r.expect_end(tk, "vertex " + std::to_string(v + 1));
                src.vertex_line[v] = r.line_no();
                src.vertex_id[v] = v + 1;
                detail::check_finite(r, p, v, v + 1);
            }
        } else if (kw == "tetrahedra") {
            if (have_tets) r.fail("a second Tetrahedra section");
            have_tets = true;
            const index_t n = r.check_count(words.next_int("the tet count"), 4, "tet");
            words.end_of_header("the tet count");
            raw.resize(4 * static_cast<std::size_t>(n));
            mesh.region.resize(n);
            src.tet_line.resize(n);
            src.tet_id.resize(n);
            for (index_t t = 0; t < n; ++t) {
                r.require_line("tet " + std::to_string(t + 1) + " of " + std::to_string(n));
                auto tk = r.tokens();
                for (int k = 0; k < 4; ++k)
                    raw[4 * static_cast<std::size_t>(t) + k] = r.next_int(tk, "vertex index");
                std::int64_t ref = 0;
                if (!tk.empty()) ref = r.next_int(tk, "tet reference");
                r.expect_end(tk, "tet " + std::to_string(t + 1));
                if (ref < std::numeric_limits<int>::min() || ref > std::numeric_limits<int>::max())
                    r.fail("tet reference " + std::to_string(ref) + " does not fit an int");
                mesh.region[t] = static_cast<int>(ref);
                src.tet_line[t] = r.line_no();
                src.tet_id[t] = t + 1;
            }
        } else {
            const std::string name(word);
            const std::int64_t count = words.next_int("the item count of section '" + detail::quote(name) + "'");
            const index_t n = r.check_count(count, 1, "'" + detail::quote(name) + "' item");
            words.end_of_header("the item count");
            for (index_t i = 0; i < n; ++i)
                r.require_line("item " + std::to_string(i + 1) + " of section " + detail::quote(name));
            skipped[detail::quote(name)] += n;
            if (report && is_element_section(kw)) report->skipped_elements += n;
        }
    }
    if (!have_vertices) r.fail("no Vertices section");
    if (!have_tets) r.fail("no Tetrahedra section");
    mesh.tets = detail::resolve_tets(path, raw, 1, mesh.num_vertices(), src.tet_line, src.tet_id);

    if (report)
        for (const auto& [name, count] : skipped) {
            if (!report->skipped_summary.empty()) report->skipped_summary += ", ";
            report->skipped_summary += std::to_string(count) + " x " + name;
        }
    return mesh;
}

}  // namespace edgefem
