// Vega FEM .veg reader: *VERTICES ("N 3 0 0", then 1-based "i x y z") and
// *ELEMENTS (TET, "T 4 0", then 1-based "i a b c d"); *MATERIAL name
// ("ENU, density, E, nu"), *SET name (element numbers, comma-separated) and
// *REGION ("set, material" lines) become per-tet regions and their
// materials. *INCLUDE is refused rather than half-supported; other sections
// are skipped with a warning.
#include <map>
#include <string>
#include <utility>
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

// The comma- or blank-separated fields of a line ("ENU, 1000, 1e5, 0.45").
std::vector<std::string_view> fields(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    const auto sep = [](char c) { return c == ',' || c == ' ' || c == '\t' || c == '\r'; };
    while (i < line.size()) {
        while (i < line.size() && sep(line[i])) ++i;
        std::size_t j = i;
        while (j < line.size() && !sep(line[j])) ++j;
        if (j > i) out.push_back(line.substr(i, j - i));
        i = j;
    }
    return out;
}

// The name after a keyword ("*MATERIAL steel" -> "steel"), failing when none.
std::string keyword_name(const detail::TextReader& r, const char* keyword) {
    const auto f = fields(r.line());
    if (f.size() < 2) r.fail(std::string("*") + keyword + " needs a name on its line");
    if (f.size() > 2) r.fail("unexpected '" + detail::quote(f[2]) + "' after the " + keyword + " name");
    return std::string(f[1]);
}

struct VegaMaterial {
    int region;
    Material material;
};
struct VegaSet {
    std::int64_t line;                                   // of the *SET keyword
    std::vector<std::pair<std::int64_t, std::int64_t>> elements;  // (element number, line)
};
struct VegaRegionLine {
    std::int64_t line;
    std::string set, material;
};

// What the material sections say, resolved once the tets are known.
struct VegaRegions {
    std::map<std::string, VegaMaterial> materials;
    std::map<std::string, VegaSet> sets;
    std::vector<VegaRegionLine> regions;
    std::vector<std::string> skipped;  // other sections: "*NAME (line L)"
};

void read_material(detail::TextReader& r, VegaRegions& v, ReadReport* report) {
    const std::string name = keyword_name(r, "MATERIAL");
    if (v.materials.count(name)) r.fail("a second *MATERIAL '" + detail::quote(name) + "'");
    r.require_line("the constants of material '" + detail::quote(name) + "' (ENU, density, E, nu)");
    const auto f = fields(r.line());
    if (f.empty())  // a line of separators only (" ,")
        r.fail("material '" + detail::quote(name) + "': expected 'ENU, density, E, nu', got no values");
    if (!detail::iequals(f[0], "ENU"))
        r.fail("material type '" + detail::quote(f[0]) + "' of material '" + detail::quote(name) +
               "' is not supported (only ENU: density, Young's modulus, Poisson ratio)");
    if (f.size() != 4)
        r.fail("material '" + detail::quote(name) + "': expected 'ENU, density, E, nu', got " +
               std::to_string(f.size() - 1) + " values");
    Material m;
    m.density = r.parse_double(f[1], "density");
    m.young = r.parse_double(f[2], "Young's modulus");
    m.poisson = r.parse_double(f[3], "Poisson ratio");
    try {
        m.validate();
    } catch (const InvalidArgument& e) {
        std::string what = e.what();
        if (what.rfind("material: ", 0) == 0) what.erase(0, 10);
        r.fail("material '" + detail::quote(name) + "': " + what);
    }
    const int region = static_cast<int>(v.materials.size()) + 1;
    v.materials[name] = {region, m};
    if (report) {
        report->materials[region] = m;
        report->material_names[region] = name;
    }
}

// Reads the lines of the section up to the next keyword; returns whether a
// keyword line follows (false at the end of the file).
template <class F>
bool section_lines(detail::TextReader& r, F&& on_line) {
    bool have = r.next_line();
    while (have && r.line().front() != '*') {
        on_line();
        have = r.next_line();
    }
    return have;
}

bool read_set(detail::TextReader& r, VegaRegions& v) {
    const std::string name = keyword_name(r, "SET");
    if (v.sets.count(name)) r.fail("a second *SET '" + detail::quote(name) + "'");
    VegaSet& set = v.sets[name];
    set.line = r.line_no();
    return section_lines(r, [&] {
        for (const std::string_view f : fields(r.line()))
            set.elements.emplace_back(r.parse_int(f, "element number in set '" + detail::quote(name) + "'"),
                                      r.line_no());
    });
}

bool read_region(detail::TextReader& r, VegaRegions& v) {
    if (fields(r.line()).size() > 1) r.fail("unexpected '" + detail::quote(fields(r.line())[1]) + "' after *REGION");
    return section_lines(r, [&] {
        const auto f = fields(r.line());
        if (f.size() != 2)
            r.fail("expected a region line 'set, material', got '" + detail::quote(r.line()) + "'");
        v.regions.push_back({r.line_no(), std::string(f[0]), std::string(f[1])});
    });
}

// Gives every tet of each *REGION's set its material's region.
void assign_regions(const detail::TextReader& r, const VegaRegions& v, Mesh& mesh, ReadReport* report) {
    if (v.regions.empty()) {
        if (!v.materials.empty() && report)
            report->warnings.push_back(r.path() + ": *MATERIAL without any *REGION: no tet uses it");
        return;
    }
    const index_t nt = static_cast<index_t>(mesh.source.tet_id.size());
    mesh.region.assign(nt, 0);
    std::vector<std::int64_t> assigned_at(nt, 0);  // region line that set the tet
    for (const VegaRegionLine& rl : v.regions) {
        const auto m = v.materials.find(rl.material);
        if (m == v.materials.end())
            r.fail_at(rl.line, "material '" + detail::quote(rl.material) + "' is not defined by a *MATERIAL");
        const auto s = v.sets.find(rl.set);
        const bool all = s == v.sets.end() && rl.set == "allElements";
        if (s == v.sets.end() && !all)
            r.fail_at(rl.line, "set '" + detail::quote(rl.set) + "' is not defined by a *SET");
        const auto give = [&](index_t t) {
            if (assigned_at[t] != 0 && mesh.region[t] != m->second.region)
                r.fail_at(rl.line, detail::item_label("tet", t, t + 1) + " is in two regions (lines " +
                                       std::to_string(assigned_at[t]) + " and " + std::to_string(rl.line) +
                                       ") with different materials",
                          t);
            mesh.region[t] = m->second.region;
            assigned_at[t] = rl.line;
        };
        if (all) {
            for (index_t t = 0; t < nt; ++t) give(t);
            continue;
        }
        for (const auto& [id, line] : s->second.elements) {
            if (id < 1 || id > nt)
                r.fail_at(line, "set '" + detail::quote(rl.set) + "': element " + std::to_string(id) +
                                    " is out of range (elements are numbered 1.." + std::to_string(nt) + ")");
            give(static_cast<index_t>(id - 1));
        }
    }
    index_t unassigned = 0;
    for (const std::int64_t a : assigned_at) unassigned += a == 0;
    if (unassigned > 0 && report)
        report->warnings.push_back(r.path() + ": " + std::to_string(unassigned) + " of " + std::to_string(nt) +
                                   " tets are in no *REGION: they keep region 0 (the default material)");
}

}  // namespace

Mesh read_vega(const std::string& path, ReadReport* report) {
    detail::TextReader r(path, '#');
    Mesh mesh;
    auto& src = mesh.source;
    src.vertex_file = src.tet_file = path;
    bool have_vertices = false, have_tets = false;
    std::vector<std::int64_t> raw;
    VegaRegions regions;
    ReadReport local;  // materials are resolved even when the caller wants no report
    ReadReport* rep = report ? report : &local;

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
            // Grown line by line (no reserve from the count): a header that
            // declares more than the file holds costs nothing.
            for (index_t v = 0; v < n; ++v) {
                r.require_line("vertex " + std::to_string(v + 1) + " of " + std::to_string(n));
                auto tk = r.tokens();
                const std::int64_t id = r.next_int(tk, "vertex number");
                check_number(r, id, v, src.vertex_line, "vertex");
                double p[3];
                p[0] = r.next_double(tk, "x coordinate");
                p[1] = r.next_double(tk, "y coordinate");
                p[2] = r.next_double(tk, "z coordinate");
                r.expect_end(tk, "the coordinates of vertex " + std::to_string(id));
                detail::check_finite(r, p, v, id);
                mesh.X.insert(mesh.X.end(), p, p + 3);
                src.vertex_line.push_back(r.line_no());
                src.vertex_id.push_back(id);
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
            for (index_t t = 0; t < n; ++t) {
                r.require_line("tet " + std::to_string(t + 1) + " of " + std::to_string(n));
                auto tk = r.tokens();
                const std::int64_t id = r.next_int(tk, "tet number");
                check_number(r, id, t, src.tet_line, "tet");
                for (int k = 0; k < 4; ++k) raw.push_back(r.next_int(tk, "vertex index"));
                r.expect_end(tk, "the 4 vertices of tet " + std::to_string(id));
                src.tet_line.push_back(r.line_no());
                src.tet_id.push_back(id);
            }
        } else if (kw == "INCLUDE") {
            r.fail("*INCLUDE is not supported; merge the included file into this one");
        } else if (kw == "MATERIAL") {
            read_material(r, regions, rep);
        } else if (kw == "SET") {
            have = read_set(r, regions);
            continue;
        } else if (kw == "REGION") {
            have = read_region(r, regions);
            continue;
        } else {
            // Other sections: their lines run to the next keyword.
            regions.skipped.push_back("*" + detail::quote(kw) + " (line " + std::to_string(r.line_no()) + ")");
            have = section_lines(r, [] {});
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
    assign_regions(r, regions, mesh, rep);
    if (!regions.skipped.empty()) {
        std::string list;
        for (const std::string& s : regions.skipped) list += (list.empty() ? "" : ", ") + s;
        rep->warnings.push_back(path + ": sections edgefem does not read were skipped: " + list);
    }
    return mesh;
}

}  // namespace edgefem
