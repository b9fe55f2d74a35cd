// Vega FEM .veg reader: *VERTICES ("N 3 0 0", then 1-based "i x y z") and
// *ELEMENTS (TET, "T 4 0", then 1-based "i a b c d"). Material, region and
// set sections are skipped; *INCLUDE is refused rather than half-supported.
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "text_reader.hpp"

namespace edgefem {

namespace {

// Reads "<count> <per-item> ..." and checks the per-item value.
index_t read_block_header(detail::TextReader& r, const char* kind, std::int64_t per_item,
                          const char* per_item_name, int min_tokens) {
    r.require_line(std::string("the ") + kind + " header line");
    auto tk = r.tokens();
    const std::int64_t n = r.next_int(tk, std::string(kind) + " count");
    if (!tk.empty()) {
        const std::int64_t value = r.next_int(tk, per_item_name);
        if (value != per_item)
            r.fail(std::string(per_item_name) + " must be " + std::to_string(per_item) + ", got " +
                   std::to_string(value));
    }
    while (!tk.empty()) r.next_int(tk, std::string(kind) + " header value");
    return r.check_count(n, min_tokens, kind);
}

// Checks that item i (0-based) is numbered i + 1.
void check_number(const detail::TextReader& r, std::int64_t id, std::int64_t i,
                  const std::vector<std::int64_t>& lines, const char* kind) {
    if (id == i + 1) return;
    if (id >= 1 && id <= i)
        r.fail(std::string("duplicate ") + kind + " number " + std::to_string(id) +
               " (first defined at line " + std::to_string(lines[id - 1]) + ")");
    r.fail(std::string(kind) + "s must be numbered 1, 2, ... consecutively: expected " +
           std::to_string(i + 1) + ", got " + std::to_string(id));
}

}  // namespace

Mesh read_vega(const std::string& path, ReadReport* /*report*/) {
    detail::TextReader r(path, '#');
    Mesh mesh;
    auto& src = mesh.source;
    src.vertex_file = src.tet_file = path;
    bool have_vertices = false, have_tets = false;
    std::vector<std::int64_t> raw;

    bool have = r.next_line();
    if (!have) r.fail(r.file_empty() ? "file is empty" : "no *VERTICES section");
    while (have) {
        if (r.line().front() != '*')
            r.fail("expected a *KEYWORD line such as *VERTICES, got '" + detail::quote(r.line()) + "'");
        auto kt = r.tokens();
        const std::string kw = detail::ascii_upper(kt.next().substr(1));
        if (kw == "VERTICES") {
            if (have_vertices) r.fail("a second *VERTICES section");
            have_vertices = true;
            const index_t n = read_block_header(r, "vertex", 3, "dimension", 4);
            mesh.X.resize(3 * static_cast<std::size_t>(n));
            src.vertex_line.resize(n);
            src.vertex_id.resize(n);
            for (index_t v = 0; v < n; ++v) {
                r.require_line("vertex " + std::to_string(v + 1) + " of " + std::to_string(n));
                auto tk = r.tokens();
                const std::int64_t id = r.next_int(tk, "vertex number");
                check_number(r, id, v, src.vertex_line, "vertex");
                double* p = &mesh.X[3 * static_cast<std::size_t>(v)];
                p[0] = r.next_double(tk, "x coordinate");
                p[1] = r.next_double(tk, "y coordinate");
                p[2] = r.next_double(tk, "z coordinate");
                r.expect_end(tk, "the coordinates of vertex " + std::to_string(id));
                src.vertex_line[v] = r.line_no();
                src.vertex_id[v] = id;
                detail::check_finite(r, p, v, id);
            }
        } else if (kw == "ELEMENTS") {
            if (have_tets) r.fail("a second *ELEMENTS section");
            have_tets = true;
            r.require_line("the element type (TET)");
            const std::string type = detail::ascii_upper(r.line());
            if (type != "TET" && type != "TETS")
                r.fail("Vega element type '" + detail::quote(r.line()) +
                       "' is not supported (only TET)");
            const index_t n = read_block_header(r, "tet", 4, "nodes per element", 5);
            raw.resize(4 * static_cast<std::size_t>(n));
            src.tet_line.resize(n);
            src.tet_id.resize(n);
            for (index_t t = 0; t < n; ++t) {
                r.require_line("tet " + std::to_string(t + 1) + " of " + std::to_string(n));
                auto tk = r.tokens();
                const std::int64_t id = r.next_int(tk, "tet number");
                check_number(r, id, t, src.tet_line, "tet");
                for (int k = 0; k < 4; ++k)
                    raw[4 * static_cast<std::size_t>(t) + k] = r.next_int(tk, "vertex index");
                r.expect_end(tk, "the 4 vertices of tet " + std::to_string(id));
                src.tet_line[t] = r.line_no();
                src.tet_id[t] = id;
            }
        } else if (kw == "INCLUDE") {
            r.fail("*INCLUDE is not supported; merge the included file into this one");
        } else {
            // *MATERIAL, *REGION, *SET, ...: their lines run to the next keyword.
            do have = r.next_line();
            while (have && r.line().front() != '*');
            continue;
        }
        have = r.next_line();
        if (have && r.line().front() != '*')
            r.fail("more lines than the section's count, or a line outside any section: '" +
                   detail::quote(r.line()) + "'");
    }
    if (!have_vertices) r.fail("no *VERTICES section");
    if (!have_tets) r.fail("no *ELEMENTS section");
    mesh.tets = detail::resolve_tets(path, raw, 1, mesh.num_vertices(), src.tet_line, src.tet_id);
    return mesh;
}

}  // namespace edgefem
