#include "edgefem/core/scene_json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/memory_estimate.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/surface_selection.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "text_reader.hpp"

namespace edgefem {

namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Messages and typed access ------------------------------------------

// "a" + "b" -> "a.b"; the top level has an empty path.
std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string item(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

// True when `v` holds at most `budget` values nested at most `depth` deep:
// small enough to quote. The budget bounds both the work and the recursion.
bool small_value(const json& v, int depth, int& budget) {
    if (--budget < 0) return false;
    if (!v.is_structured()) return true;
    if (depth == 0) return false;
    for (const json& e : v)
        if (!small_value(e, depth - 1, budget)) return false;
    return true;
}

// A value as it appears in the file, shortened for messages. Large or deep
// containers are only described: json::dump recurses once per level.
std::string show(const json& v) {
    int budget = 32;
    if (!small_value(v, 3, budget)) {
        const std::string n = std::to_string(v.size()), s = v.size() == 1 ? "" : "s";
        return v.is_array() ? "an array of " + n + " value" + s : "an object with " + n + " key" + s;
    }
    std::string s = v.dump();
    if (s.size() > 60) s = s.substr(0, 57) + "...";
    return s;
}

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

// What the parser needs besides the JSON: where paths resolve and what
// messages start with.
struct Context {
    std::string source;
    std::string base_dir;

    [[noreturn]] void fail(const std::string& key, const std::string& message) const {
        throw InvalidArgument(printable(source) + ": \"" + printable(key) + "\": " + printable(message));
    }

    std::string resolve(const std::string& p) const {
        if (base_dir.empty() || fs::path(p).is_absolute()) return p;
        return (fs::path(base_dir) / p).lexically_normal().string();
    }
};

// Fails on keys outside `allowed` (typos must not pass silently).
void check_keys(const Context& cx, const json& obj, const std::string& path,
                std::initializer_list<const char*> allowed) {
    if (!obj.is_object()) cx.fail(path, "expected an object, got " + show(obj));
    for (const auto& item : obj.items()) {
        const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture those
        if (std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) continue;
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        cx.fail(join(path, key), "unknown key (expected one of: " + list + ")");
    }
}

const json* find(const json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
}

enum class Range { Finite, Positive, NonNegative };

double get_number(const Context& cx, const json& v, const std::string& path, Range range = Range::Finite) {
    const char* want = range == Range::Positive      ? "a positive number"
                       : range == Range::NonNegative ? "a non-negative number"
                                                     : "a number";
    if (!v.is_number()) cx.fail(path, std::string("expected ") + want + ", got " + show(v));
    const double x = v.get<double>();
    if (!std::isfinite(x) || (range == Range::Positive && !(x > 0)) || (range == Range::NonNegative && !(x >= 0)))
        cx.fail(path, std::string("expected ") + want + ", got " + show(v));
    return x;
}

// 2^63: the first double past int64 (double(INT64_MAX) rounds up to it).
constexpr double kTwo63 = 9223372036854775808.0;

// Integers may be written as 1000 or 1e3, not as 2.5. Ranges are compared as
// integers: a double cannot hold every int64, so comparing doubles would let
// INT64_MAX through and overflow the cast.
std::int64_t get_integer(const Context& cx, const json& v, const std::string& path, std::int64_t min,
                         std::int64_t max = std::numeric_limits<int>::max()) {
    const std::string want = min == 0 ? "a non-negative integer" : min == 1 ? "a positive integer"
                                                                            : "an integer >= " + std::to_string(min);
    const auto too_big = [&] { cx.fail(path, "expected " + want + " up to " + std::to_string(max) + ", got " + show(v)); };
    std::int64_t i = 0;
    if (v.is_number_unsigned()) {
        if (v.get<std::uint64_t>() > std::uint64_t(max)) too_big();
        i = std::int64_t(v.get<std::uint64_t>());
    } else if (v.is_number_integer()) {
        i = v.get<std::int64_t>();
    } else if (v.is_number_float()) {
        const double x = v.get<double>();
        if (!std::isfinite(x) || x != std::floor(x) || x < -kTwo63) cx.fail(path, "expected " + want + ", got " + show(v));
        if (x >= kTwo63) too_big();
        i = static_cast<std::int64_t>(x);
    } else {
        cx.fail(path, "expected " + want + ", got " + show(v));
    }
    if (i < min) cx.fail(path, "expected " + want + ", got " + show(v));
    if (i > max) too_big();
    return i;
}

int get_int(const Context& cx, const json& v, const std::string& path, int min) {
    return static_cast<int>(get_integer(cx, v, path, min));
}

bool get_bool(const Context& cx, const json& v, const std::string& path) {
    if (!v.is_boolean()) cx.fail(path, "expected true or false, got " + show(v));
    return v.get<bool>();
}

std::string get_string(const Context& cx, const json& v, const std::string& path) {
    if (!v.is_string() || v.get<std::string>().empty()) cx.fail(path, "expected a non-empty string, got " + show(v));
    return v.get<std::string>();
}

template <class E>
E get_enum(const Context& cx, const json& v, const std::string& path,
           const std::vector<std::pair<const char*, E>>& names) {
    if (v.is_string())
        for (const auto& [name, e] : names)
            if (v.get<std::string>() == name) return e;
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "\"" : ", \"") + std::string(n.first) + "\"";
    cx.fail(path, "expected one of " + list + ", got " + show(v));
}

std::array<double, 3> get_vec3(const Context& cx, const json& v, const std::string& path) {
    if (!v.is_array() || v.size() != 3) cx.fail(path, "expected an array of 3 numbers, got " + show(v));
    std::array<double, 3> out;
    for (std::size_t i = 0; i < 3; ++i) out[i] = get_number(cx, v[i], item(path, i));
    return out;
}

// ---- Mesh ------------------------------------------------------------------

// "box:NXxNYxNZ" (0.01 m cubes, as on the command line).
Mesh box_from_spec(const Context& cx, const std::string& spec, const std::string& path) {
    try {
        return make_box_from_spec(spec);
    } catch (const InvalidArgument& e) {
        cx.fail(path, e.what());
    }
}

// The scene's mesh; `report` gets what the reader noticed (warnings, the
// file's own materials, higher-order tets).
Mesh read_scene_mesh(const Context& cx, const json& v, ReadReport& report) {
    const std::string key = "mesh";
    try {
        if (v.is_string()) {
            const std::string s = get_string(cx, v, key);
            if (is_box_spec(s)) return box_from_spec(cx, s, key);
            const std::string path = cx.resolve(s);
            Mesh m = read_mesh(path, MeshFormat::Auto, &report);
            try {
                check_memory(path, m.num_tets());
            } catch (const InvalidArgument& e) {
                cx.fail(key, e.what());
            }
            return m;
        }
        check_keys(cx, v, key, {"box"});
        const json* box = find(v, "box");
        if (!box) cx.fail(key, "expected a path, \"box:NXxNYxNZ\" or {\"box\": {\"cells\": [nx, ny, nz], \"cell\": h}}");
        const std::string bkey = join(key, "box");
        check_keys(cx, *box, bkey, {"cells", "cell"});
        const json* cells = find(*box, "cells");
        if (!cells) cx.fail(join(bkey, "cells"), "required key missing");
        if (!cells->is_array() || cells->size() != 3)
            cx.fail(join(bkey, "cells"), "expected an array of 3 positive integers, got " + show(*cells));
        index_t n[3];
        for (std::size_t i = 0; i < 3; ++i) n[i] = index_t(get_integer(cx, (*cells)[i], item(join(bkey, "cells"), i), 1));
        const json* cell = find(*box, "cell");
        const double h = cell ? get_number(cx, *cell, join(bkey, "cell"), Range::Positive) : 0.01;
        try {
            return make_box(n[0], n[1], n[2], h);
        } catch (const InvalidArgument& e) {
            cx.fail(bkey, e.what());  // e.g. too many tets
        }
    } catch (const MeshError& e) {
        // The key and scene file first, then the mesh file's own file:line.
        throw MeshError(cx.source + ": \"" + key + "\": " + e.what(), {}, 0, e.element());
    }
}

// ---- Vertex selections -----------------------------------------------------

// Maps the mesh's vertex numbering as read to the numbering after
// validation (compaction removes unused vertices, keeping the order).
struct Renumbering {
    index_t read_count = 0;
    std::vector<index_t> to_final;  // empty: identity

    index_t operator()(index_t v) const { return to_final.empty() ? v : to_final[v]; }
};

Renumbering compaction_map(const Mesh& read, bool compact) {
    Renumbering r;
    r.read_count = read.num_vertices();
    if (!compact) return r;
    std::vector<char> used(r.read_count, 0);
    for (index_t v : read.tets)
        if (v >= 0 && v < r.read_count) used[v] = 1;
    r.to_final.assign(r.read_count, -1);
    index_t next = 0;
    for (index_t v = 0; v < r.read_count; ++v)
        if (used[v]) r.to_final[v] = next++;
    return r;
}

std::string out_of_range(const std::string& v, index_t count) {
    return "vertex " + v + " out of range (mesh has " + std::to_string(count) + " vertices)";
}

std::string out_of_range(std::int64_t v, index_t count) { return out_of_range(std::to_string(v), count); }

// A vertex index of the mesh as read: any integer from `count` up is out of
// range, including whole numbers past int64 written as floats (9.3e18).
index_t get_vertex(const Context& cx, const json& v, const std::string& path, index_t count) {
    const bool huge = (v.is_number_float() && v.get<double>() >= kTwo63) ||
                      (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<std::int64_t>::max()));
    if (huge) cx.fail(path, out_of_range(show(v), count));
    const std::int64_t i = get_integer(cx, v, path, 0, std::numeric_limits<std::int64_t>::max());
    if (i >= count) cx.fail(path, out_of_range(i, count));
    return index_t(i);
}

// One parsed line of a fixed (index) or prescribed (index x y z) file.
struct IndexLine {
    index_t vertex;
    std::array<double, 3> xyz;
    std::int64_t line;
};

// The one parser of both files: '#' comments and blank lines skipped, every
// other line exactly `1 + coords` tokens with an in-range vertex index.
std::vector<IndexLine> read_index_file(const Context& cx, const std::string& key, const std::string& file,
                                       int coords, index_t count) {
    const std::string path = cx.resolve(file);
    const char* what = coords ? "'index x y z'" : "a vertex index";
    std::vector<IndexLine> out;
    try {
        detail::TextReader r(path, '#', coords ? "prescribed-vertex file" : "fixed-vertex file");
        while (r.next_line()) {
            auto tok = r.tokens();
            IndexLine l{};
            l.line = r.line_no();
            const std::int64_t v = r.next_int(tok, "vertex index");
            if (v < 0 || v >= count) r.fail(out_of_range(v, count));
            l.vertex = index_t(v);
            for (int c = 0; c < coords; ++c) {
                l.xyz[c] = r.next_double(tok, "coordinate");
                if (!std::isfinite(l.xyz[c])) r.fail("non-finite coordinate");
            }
            r.expect_end(tok, what);
            out.push_back(l);
        }
        if (out.empty()) r.fail(std::string("no lines: expected ") + what + " per line");
    } catch (const MeshError& e) {
        cx.fail(key, e.what());
    }
    return out;
}

// Every vertex whose rest position lies in [lo, hi] (bounds inclusive).
std::vector<index_t> select_in_box(const Mesh& mesh, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
    std::vector<index_t> out;
    for (index_t v = 0; v < mesh.num_vertices(); ++v) {
        const double* x = &mesh.X[3 * std::size_t(v)];
        bool in = true;
        for (int c = 0; c < 3; ++c) in = in && x[c] >= lo[c] && x[c] <= hi[c];
        if (in) out.push_back(v);
    }
    return out;
}

// {"min": [x, y, z], "max": [x, y, z]}, each side unbounded when left out.
std::pair<std::array<double, 3>, std::array<double, 3>> read_box(const Context& cx, const json& box, const std::string& key) {
    check_keys(cx, box, key, {"min", "max"});
    std::array<double, 3> lo{-kInf, -kInf, -kInf}, hi{kInf, kInf, kInf};
    if (const json* m = find(box, "min")) lo = get_vec3(cx, *m, join(key, "min"));
    if (const json* m = find(box, "max")) hi = get_vec3(cx, *m, join(key, "max"));
    for (int c = 0; c < 3; ++c)
        if (lo[c] > hi[c]) cx.fail(key, "min[" + std::to_string(c) + "] = " + num(lo[c]) + " exceeds max[" + std::to_string(c) + "] = " + num(hi[c]));
    return {lo, hi};
}

// {"surface": TAG | "NAME"}: the mesh file's triangles with that tag (Gmsh
// physical surface, TetGen boundary marker, MEDIT reference) or Gmsh
// physical name, in the file's winding.
std::vector<Triangle> tagged_surface(const Context& cx, const json& v, const std::string& path, const Mesh& mesh) {
    if (!v.is_string() && !v.is_number())
        cx.fail(path, "expected a surface tag (an integer) or a physical name (a string), got " + show(v));
    const int tag = v.is_number() ? static_cast<int>(get_integer(cx, v, path, std::numeric_limits<int>::min())) : 0;
    try {
        return tagged_triangles(mesh, v.is_string() ? tags_named(mesh, v.get<std::string>()) : std::vector<int>{tag});
    } catch (const InvalidArgument& e) {
        cx.fail(path, e.what());
    }
}

// {"boundary": true}.
void check_boundary_flag(const Context& cx, const json& v, const std::string& path) {
    if (!get_bool(cx, v, path)) cx.fail(path, "expected true (the whole boundary), got false");
}

// One vertex selector ("fixed", "prescribed.select"): {"file": PATH} | {"vertices": [...]} | {"box": {...}}
// | {"surface": TAG | NAME} | {"boundary": true}.
void add_selected(const Context& cx, const json& sel, const std::string& path, const Mesh& mesh,
               const Renumbering& renumber, std::vector<index_t>& fixed) {
    check_keys(cx, sel, path, {"file", "vertices", "box", "surface", "boundary"});
    if (sel.size() != 1) cx.fail(path, "expected exactly one of \"file\", \"vertices\", \"box\", \"surface\", \"boundary\" (use an array of selectors to combine them), got " + show(sel));
    const std::size_t before = fixed.size();
    const auto add = [&](index_t v) {
        if (renumber(v) >= 0) fixed.push_back(renumber(v));  // compaction dropped unused vertices
    };
    if (const json* f = find(sel, "file")) {
        const std::string key = join(path, "file");
        for (const IndexLine& l : read_index_file(cx, key, get_string(cx, *f, key), 0, renumber.read_count)) add(l.vertex);
    } else if (const json* vs = find(sel, "vertices")) {
        const std::string key = join(path, "vertices");
        if (!vs->is_array() || vs->empty()) cx.fail(key, "expected a non-empty array of vertex indices, got " + show(*vs));
        for (std::size_t i = 0; i < vs->size(); ++i) {
            add(get_vertex(cx, (*vs)[i], item(key, i), renumber.read_count));
        }
    } else if (const json* t = find(sel, "surface")) {
        const std::vector<index_t> in = triangle_vertices(tagged_surface(cx, *t, join(path, "surface"), mesh));
        fixed.insert(fixed.end(), in.begin(), in.end());
    } else if (const json* b = find(sel, "boundary")) {
        check_boundary_flag(cx, *b, join(path, "boundary"));
        const std::vector<index_t> in = boundary_surface(mesh).vertices();
        fixed.insert(fixed.end(), in.begin(), in.end());
    } else {
        const auto [lo, hi] = read_box(cx, sel["box"], join(path, "box"));
        const std::vector<index_t> in = select_in_box(mesh, lo, hi);
        fixed.insert(fixed.end(), in.begin(), in.end());
    }
    if (fixed.size() == before) cx.fail(path, "selects no vertex");
}

// A selector or a non-empty array of selectors (united): the vertices, ascending.
std::vector<index_t> select_vertices(const Context& cx, const json& v, const std::string& path, const Mesh& mesh,
                                     const Renumbering& renumber) {
    std::vector<index_t> out;
    if (v.is_array()) {
        if (v.empty()) cx.fail(path, "expected a selector or a non-empty array of selectors, got []");
        for (std::size_t i = 0; i < v.size(); ++i) add_selected(cx, v[i], item(path, i), mesh, renumber, out);
    } else {
        add_selected(cx, v, path, mesh, renumber, out);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

// One surface selector of a surface load: {"surface": TAG | NAME} |
// {"boundary": true} | {"box": {...}} (the boundary triangles whose three
// vertices lie in it); the triangles wound outward.
void add_surface(const Context& cx, const json& sel, const std::string& path, const Mesh& mesh,
                 std::vector<Triangle>& out) {
    check_keys(cx, sel, path, {"surface", "boundary", "box"});
    if (sel.size() != 1)
        cx.fail(path, "expected exactly one of \"surface\", \"boundary\", \"box\" (use an array of selectors to combine them), got " + show(sel));
    std::vector<Triangle> tri;
    if (const json* t = find(sel, "surface")) {
        const std::string key = join(path, "surface");
        const std::vector<Triangle> tagged = tagged_surface(cx, *t, key, mesh);
        try {
            tri = orient_outward(mesh, tagged);
        } catch (const MeshError& e) {
            cx.fail(key, e.what());
        }
    } else if (const json* b = find(sel, "boundary")) {
        check_boundary_flag(cx, *b, join(path, "boundary"));
        tri = boundary_surface(mesh).triangles;
    } else {
        const auto [lo, hi] = read_box(cx, sel["box"], join(path, "box"));
        tri = boundary_in_box(mesh, lo, hi);
        if (tri.empty()) cx.fail(join(path, "box"), "selects no boundary triangle (all three vertices must lie in the box)");
    }
    out.insert(out.end(), tri.begin(), tri.end());
}

// ---- The scene ---------------------------------------------------------

Material read_material(const Context& cx, const json& v, const std::string& path, Material m) {
    check_keys(cx, v, path, {"young", "poisson", "density"});
    if (const json* x = find(v, "young")) m.young = get_number(cx, *x, join(path, "young"), Range::Positive);
    if (const json* x = find(v, "poisson")) {
        m.poisson = get_number(cx, *x, join(path, "poisson"));
        if (!(m.poisson > -1 && m.poisson < 0.5)) cx.fail(join(path, "poisson"), "expected a number in (-1, 0.5), got " + show(*x));
    }
    if (const json* x = find(v, "density")) m.density = get_number(cx, *x, join(path, "density"), Range::Positive);
    return m;
}

void read_solver(const Context& cx, const json& v, SolverSettings& s) {
    const std::string p = "solver";
    check_keys(cx, v, p,
               {"linear", "preconditioner", "auto_amg_iterations", "amg_refresh_interval", "cg_tolerance", "cg_max_iterations", "cg_fixed_iterations", "warm_start", "definite_stiffness",
                "newton_tolerance", "newton_max_iterations", "load_steps", "max_step_halvings",
                "stiffness_interval", "fail_on_unconverged", "max_energy_growth", "fail_on_inverted"});
    if (const json* x = find(v, "fail_on_inverted")) s.fail_on_inverted = get_bool(cx, *x, join(p, "fail_on_inverted"));
    if (const json* x = find(v, "linear"))
        s.linear_solver = get_enum<LinearSolver>(cx, *x, join(p, "linear"), {{"cg", LinearSolver::CG}, {"direct", LinearSolver::Direct}});
    if (const json* x = find(v, "preconditioner"))
        s.preconditioner = get_enum<PreconditionerKind>(cx, *x, join(p, "preconditioner"),
                                                        {{"auto", PreconditionerKind::Auto},
                                                         {"block-jacobi", PreconditionerKind::BlockJacobi},
                                                         {"amg", PreconditionerKind::Amg}});
    if (const json* x = find(v, "auto_amg_iterations"))
        s.auto_amg_iterations = get_int(cx, *x, join(p, "auto_amg_iterations"), 1);
    if (const json* x = find(v, "amg_refresh_interval"))
        s.amg_refresh_interval = get_int(cx, *x, join(p, "amg_refresh_interval"), 0);
    if (const json* x = find(v, "cg_tolerance")) s.cg_tolerance = get_number(cx, *x, join(p, "cg_tolerance"), Range::Positive);
    if (const json* x = find(v, "cg_max_iterations")) s.cg_max_iterations = get_int(cx, *x, join(p, "cg_max_iterations"), 1);
    if (const json* x = find(v, "cg_fixed_iterations")) s.cg_fixed_iterations = get_int(cx, *x, join(p, "cg_fixed_iterations"), 0);
    if (const json* x = find(v, "warm_start")) s.warm_start = get_bool(cx, *x, join(p, "warm_start"));
    if (const json* x = find(v, "definite_stiffness")) s.definite_stiffness = get_bool(cx, *x, join(p, "definite_stiffness"));
    if (const json* x = find(v, "fail_on_unconverged")) s.fail_on_unconverged = get_bool(cx, *x, join(p, "fail_on_unconverged"));
    if (const json* x = find(v, "newton_tolerance")) s.newton_tolerance = get_number(cx, *x, join(p, "newton_tolerance"), Range::Positive);
    if (const json* x = find(v, "newton_max_iterations")) s.newton_max_iterations = get_int(cx, *x, join(p, "newton_max_iterations"), 1);
    if (const json* x = find(v, "load_steps")) s.load_steps = get_int(cx, *x, join(p, "load_steps"), 1);
    if (const json* x = find(v, "max_step_halvings")) s.max_step_halvings = get_int(cx, *x, join(p, "max_step_halvings"), 0);
    if (const json* x = find(v, "stiffness_interval")) s.stiffness_interval = get_int(cx, *x, join(p, "stiffness_interval"), 1);
    if (const json* x = find(v, "max_energy_growth")) {
        const std::string key = join(p, "max_energy_growth");
        s.max_energy_growth = get_number(cx, *x, key, Range::NonNegative);
        if (s.max_energy_growth != 0 && s.max_energy_growth < 1) cx.fail(key, "expected 0 (off) or a number >= 1, got " + show(*x));
    }
}

constexpr std::pair<const char*, OutputFormat> kOutputFormats[] = {
    {"binary", OutputFormat::Binary}, {"ascii", OutputFormat::Ascii}, {"ply", OutputFormat::Ply}, {"obj", OutputFormat::Obj}};

// Empty when `name` is a format that suits `mesh` (then in `out`), else why not.
std::string output_format_error(const std::string& name, OutputMesh mesh, OutputFormat& out) {
    for (const auto& [n, f] : kOutputFormats) {
        if (name != n) continue;
        if ((f == OutputFormat::Ply || f == OutputFormat::Obj) && mesh != OutputMesh::Surface)
            return "\"" + name + "\" holds triangles only: it needs \"output.mesh\": \"surface\"";
        out = f;
        return {};
    }
    return "expected one of \"binary\", \"ascii\", \"ply\", \"obj\", got '" + printable(name) + "'";
}

OutputFields read_output_fields(const Context& cx, const json& v, const std::string& path) {
    if (!v.is_array()) cx.fail(path, "expected an array of field names, got " + show(v));
    OutputFields f{false, false, false, false, false, false, false};
    const std::pair<const char*, bool OutputFields::*> names[] = {
        {"displacement", &OutputFields::displacement}, {"velocity", &OutputFields::velocity},
        {"force", &OutputFields::force},               {"energy_density", &OutputFields::energy_density},
        {"green_strain", &OutputFields::green_strain}, {"pk2_stress", &OutputFields::pk2_stress},
        {"von_mises", &OutputFields::von_mises}};
    for (std::size_t i = 0; i < v.size(); ++i) {
        const auto it = std::find_if(std::begin(names), std::end(names), [&](const auto& n) {
            return v[i].is_string() && v[i].get<std::string>() == n.first;
        });
        if (it == std::end(names)) {
            std::string list;
            for (const auto& n : names) list += (list.empty() ? "" : ", ") + std::string(n.first);
            cx.fail(item(path, i), "unknown field " + show(v[i]) + " (expected one of: " + list + ")");
        }
        if (f.*(it->second)) cx.fail(item(path, i), "field " + show(v[i]) + " listed twice");
        f.*(it->second) = true;
    }
    return f;
}

void read_output(const Context& cx, const json& v, OutputSettings& o) {
    const std::string p = "output";
    check_keys(cx, v, p, {"dir", "every", "vtu", "format", "mesh", "fields"});
    if (const json* x = find(v, "dir")) o.dir = get_string(cx, *x, join(p, "dir"));  // relative to the current directory
    if (const json* x = find(v, "every")) o.every = get_int(cx, *x, join(p, "every"), 1);
    if (const json* x = find(v, "vtu")) o.vtu = get_bool(cx, *x, join(p, "vtu"));
    if (const json* x = find(v, "mesh"))
        o.mesh = get_enum<OutputMesh>(cx, *x, join(p, "mesh"), {{"volume", OutputMesh::Volume}, {"surface", OutputMesh::Surface}});
    if (const json* x = find(v, "format")) {
        const std::string key = join(p, "format");
        if (!x->is_string()) cx.fail(key, "expected one of \"binary\", \"ascii\", \"ply\", \"obj\", got " + show(*x));
        if (const std::string error = output_format_error(x->get<std::string>(), o.mesh, o.format); !error.empty())
            cx.fail(key, error);
    }
    if (const json* x = find(v, "fields")) o.fields = read_output_fields(cx, *x, join(p, "fields"));
}

// [[t, value], ...] with strictly increasing times.
std::vector<Keyframe> read_keyframes(const Context& cx, const json& v, const std::string& path) {
    if (!v.is_array() || v.empty()) cx.fail(path, "expected a non-empty array of [time, value] pairs, got " + show(v));
    std::vector<Keyframe> keys;
    for (std::size_t k = 0; k < v.size(); ++k) {
        const std::string key = item(path, k);
        if (!v[k].is_array() || v[k].size() != 2) cx.fail(key, "expected [time, value], got " + show(v[k]));
        keys.push_back({get_number(cx, v[k][0], item(key, 0)), get_number(cx, v[k][1], item(key, 1))});
        if (k > 0 && !(keys[k].time > keys[k - 1].time)) cx.fail(item(key, 0), "times must increase strictly");
    }
    return keys;
}

// A file of `index x y z` lines: one vector per listed vertex (3 #V, zero
// where not listed; a vertex listed twice is an error).
std::vector<double> read_vertex_vectors(const Context& cx, const std::string& key, const std::string& file,
                                        const Renumbering& renumber, const Mesh& mesh) {
    std::vector<double> out(mesh.X.size(), 0.0);
    std::map<index_t, std::int64_t> seen;
    for (const IndexLine& l : read_index_file(cx, key, file, 3, renumber.read_count)) {
        if (const auto [it, fresh] = seen.emplace(l.vertex, l.line); !fresh)
            cx.fail(key, cx.resolve(file) + ":" + std::to_string(l.line) + ": vertex " + std::to_string(l.vertex) +
                             " already listed on line " + std::to_string(it->second));
        const index_t v = renumber(l.vertex);
        if (v >= 0)
            for (int r = 0; r < 3; ++r) out[3 * std::size_t(v) + r] = l.xyz[r];
    }
    return out;
}

void read_prescribed(const Context& cx, const json& v, const Renumbering& renumber, Scene& scene) {
    const std::string p = "prescribed";
    check_keys(cx, v, p, {"file", "select", "displacement", "steps", "keyframes"});
    const json* f = find(v, "file");
    const json* sel = find(v, "select");
    const json* d = find(v, "displacement");
    if (!f && !sel) cx.fail(join(p, "file"), "required key missing (or \"select\" with \"displacement\")");
    if (sel && !d) cx.fail(join(p, "displacement"), "required key missing (with \"select\")");
    if (d && !sel) cx.fail(join(p, "displacement"), "applies only to the vertices of \"select\"");
    if (f) {
        const std::string key = join(p, "file");
        const std::string file = get_string(cx, *f, key);
        std::map<index_t, std::int64_t> seen;  // vertex -> line
        for (const IndexLine& l : read_index_file(cx, key, file, 3, renumber.read_count)) {
            if (const auto [it, fresh] = seen.emplace(l.vertex, l.line); !fresh)
                cx.fail(key, cx.resolve(file) + ":" + std::to_string(l.line) + ": vertex " + std::to_string(l.vertex) +
                                 " already prescribed on line " + std::to_string(it->second));
            if (renumber(l.vertex) >= 0) scene.prescribed.push_back({renumber(l.vertex), l.xyz});
        }
    }
    if (sel) {
        // Every selected vertex moves by the same displacement (m).
        const std::array<double, 3> u = get_vec3(cx, *d, join(p, "displacement"));
        for (const index_t vtx : select_vertices(cx, *sel, join(p, "select"), scene.mesh, renumber)) {
            const double* X = &scene.mesh.X[3 * std::size_t(vtx)];
            scene.prescribed.push_back({vtx, {X[0] + u[0], X[1] + u[1], X[2] + u[2]}});
        }
    }
    if (const json* s = find(v, "steps")) scene.prescribed_steps = get_int(cx, *s, join(p, "steps"), 1);
    if (const json* k = find(v, "keyframes")) scene.prescribed_keyframes = read_keyframes(cx, *k, join(p, "keyframes"));
}

// "load": {"file": PATH of `index fx fy fz` lines (N), "keyframes": [...]}.
void read_load(const Context& cx, const json& v, const Renumbering& renumber, Scene& scene) {
    check_keys(cx, v, "load", {"file", "keyframes"});
    const json* f = find(v, "file");
    if (!f) cx.fail("load.file", "required key missing");
    scene.load = read_vertex_vectors(cx, "load.file", get_string(cx, *f, "load.file"), renumber, scene.mesh);
    if (const json* k = find(v, "keyframes")) scene.load_keyframes = read_keyframes(cx, *k, "load.keyframes");
}

// "surface_loads": [{"on": SELECTOR | [SELECTOR, ...], "pressure": p,
// "traction": [tx, ty, tz], "keyframes": [...]}, ...].
void read_surface_loads(const Context& cx, const json& v, Scene& scene) {
    const std::string p = "surface_loads";
    if (!v.is_array() || v.empty()) cx.fail(p, "expected a non-empty array of surface loads, got " + show(v));
    for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string key = item(p, i);
        const json& e = v[i];
        check_keys(cx, e, key, {"on", "pressure", "traction", "keyframes"});
        const json* on = find(e, "on");
        if (!on) cx.fail(join(key, "on"), "required key missing");
        const json* pr = find(e, "pressure");
        const json* tr = find(e, "traction");
        if (!pr && !tr) cx.fail(key, "expected \"pressure\" or \"traction\" (or both)");
        SurfaceLoad load;
        std::vector<Triangle> tri;
        if (on->is_array()) {
            if (on->empty()) cx.fail(join(key, "on"), "expected a selector or a non-empty array of selectors, got []");
            for (std::size_t k = 0; k < on->size(); ++k) add_surface(cx, (*on)[k], item(join(key, "on"), k), scene.mesh, tri);
        } else {
            add_surface(cx, *on, join(key, "on"), scene.mesh, tri);
        }
        // Selectors unite: a triangle selected twice is loaded once.
        std::set<std::array<index_t, 3>> seen;
        for (const Triangle& t : tri) {
            std::array<index_t, 3> k = t;
            std::sort(k.begin(), k.end());
            if (seen.insert(k).second) load.triangles.push_back(t);
        }
        if (pr) load.pressure = get_number(cx, *pr, join(key, "pressure"));
        if (tr) load.traction = get_vec3(cx, *tr, join(key, "traction"));
        if (const json* k = find(e, "keyframes")) load.keyframes = read_keyframes(cx, *k, join(key, "keyframes"));
        scene.surface_loads.push_back(std::move(load));
    }
}

// "initial": {"displacement": {"file": PATH}, "velocity": [vx, vy, vz] |
// {"file": PATH} | {"angular": [wx, wy, wz], "center": [x, y, z],
// "linear": [vx, vy, vz]}} (a rigid motion: v = linear + w x (X - center)).
void read_initial(const Context& cx, const json& v, const Renumbering& renumber, Scene& scene) {
    check_keys(cx, v, "initial", {"displacement", "velocity"});
    const Mesh& m = scene.mesh;
    if (const json* d = find(v, "displacement")) {
        check_keys(cx, *d, "initial.displacement", {"file"});
        const json* f = find(*d, "file");
        if (!f) cx.fail("initial.displacement.file", "required key missing");
        scene.initial_displacement = read_vertex_vectors(cx, "initial.displacement.file",
                                                         get_string(cx, *f, "initial.displacement.file"), renumber, m);
    }
    const json* w = find(v, "velocity");
    if (!w) return;
    const std::string p = "initial.velocity";
    std::vector<double>& out = scene.initial_velocity;
    if (w->is_array()) {
        const std::array<double, 3> u = get_vec3(cx, *w, p);
        out.resize(m.X.size());
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = u[i % 3];
        return;
    }
    if (!w->is_object()) cx.fail(p, "expected [vx, vy, vz] or an object, got " + show(*w));
    if (const json* f = find(*w, "file")) {
        check_keys(cx, *w, p, {"file"});
        out = read_vertex_vectors(cx, join(p, "file"), get_string(cx, *f, join(p, "file")), renumber, m);
        return;
    }
    check_keys(cx, *w, p, {"angular", "center", "linear"});
    std::array<double, 3> om{0, 0, 0}, c{0, 0, 0}, lin{0, 0, 0};
    if (const json* x = find(*w, "angular")) om = get_vec3(cx, *x, join(p, "angular"));
    if (const json* x = find(*w, "center")) c = get_vec3(cx, *x, join(p, "center"));
    if (const json* x = find(*w, "linear")) lin = get_vec3(cx, *x, join(p, "linear"));
    out.resize(m.X.size());
    for (std::size_t a = 0; a < out.size() / 3; ++a) {
        const double r[3] = {m.X[3 * a] - c[0], m.X[3 * a + 1] - c[1], m.X[3 * a + 2] - c[2]};
        out[3 * a] = lin[0] + om[1] * r[2] - om[2] * r[1];
        out[3 * a + 1] = lin[1] + om[2] * r[0] - om[0] * r[2];
        out[3 * a + 2] = lin[2] + om[0] * r[1] - om[1] * r[0];
    }
}

SceneFile parse(const Context& cx, const json& root) {
    if (!root.is_object()) throw InvalidArgument(cx.source + ": expected a JSON object at the top level, got " + show(root));
    check_keys(cx, root, "",
               {"mesh", "mesh_options", "material", "regions", "model", "method", "gravity", "damping", "fixed",
                "prescribed", "load", "surface_loads", "initial", "integrator", "newmark", "generalized_alpha", "dt", "steps", "solver",
                "output"});
    SceneFile sf;
    Scene& s = sf.scene;

    // The mesh first: the selectors need it.
    ValidationOptions vopt;
    vopt.fix_orientation_hint = "set mesh_options.fix_orientation";
    vopt.compact_hint = "set mesh_options.compact";
    if (const json* o = find(root, "mesh_options")) {
        check_keys(cx, *o, "mesh_options", {"fix_orientation", "compact"});
        if (const json* x = find(*o, "fix_orientation")) vopt.fix_orientation = get_bool(cx, *x, "mesh_options.fix_orientation");
        if (const json* x = find(*o, "compact")) vopt.compact_unreferenced = get_bool(cx, *x, "mesh_options.compact");
    }
    const json* mesh = find(root, "mesh");
    if (!mesh) cx.fail("mesh", "required key missing");
    ReadReport read;
    s.mesh = read_scene_mesh(cx, *mesh, read);
    sf.warnings.insert(sf.warnings.end(), read.warnings.begin(), read.warnings.end());
    // Higher-order tets keep their corners: the other nodes, unreferenced,
    // are dropped as compact would (the file's numbering stays that of
    // selections, and file_vertex maps the output back to it).
    if (read.high_order_tets) vopt.compact_unreferenced = true;
    const Renumbering renumber = compaction_map(s.mesh, vopt.compact_unreferenced);
    try {
        const ValidationReport report = validate_mesh(s.mesh, vopt);
        sf.warnings.insert(sf.warnings.end(), report.warnings.begin(), report.warnings.end());
        if (report.unreferenced_vertices > 0 && !vopt.compact_unreferenced) {
            std::vector<char> used(s.mesh.num_vertices(), 0);
            for (const index_t v : s.mesh.tets) used[v] = 1;
            const auto first = std::find(used.begin(), used.end(), 0) - used.begin();
            cx.fail("mesh", s.mesh.describe_vertex(static_cast<index_t>(first)) + " is used by no tet (it would have no mass; " +
                                std::to_string(report.unreferenced_vertices) +
                                " such vertices in all); set mesh_options.compact to remove them");
        }
    } catch (const MeshError& e) {
        throw MeshError(cx.source + ": \"mesh\": " + e.what(), {}, 0, e.element());
    }
    if (!renumber.to_final.empty() && s.mesh.num_vertices() < renumber.read_count) {
        sf.file_vertex.resize(s.mesh.num_vertices());
        for (index_t v = 0; v < renumber.read_count; ++v)
            if (renumber.to_final[v] >= 0) sf.file_vertex[renumber.to_final[v]] = v;
    }

    if (const json* x = find(root, "material")) s.materials.fallback = read_material(cx, *x, "material", Material{});
    // The mesh file's own materials (Vega *MATERIAL / *REGION) hold for their
    // regions; "regions" overrides them.
    if (!read.materials.empty()) {
        std::string list;
        for (const auto& [region, m] : read.materials) {
            s.materials.by_region[region] = m;
            list += (list.empty() ? "" : ", ") + std::to_string(region) + " (" + read.material_names[region] + ")";
        }
        sf.warnings.push_back(cx.source + ": \"mesh\": the mesh file's materials are used for regions " + list);
    }
    if (const json* x = find(root, "regions")) {
        if (!x->is_object()) cx.fail("regions", "expected an object {\"<region id>\": {material}, ...}, got " + show(*x));
        std::set<int> present;
        for (index_t t = 0; t < s.mesh.num_tets(); ++t) present.insert(s.mesh.tet_region(t));
        for (const auto& [id, m] : x->items()) {
            const std::string key = join("regions", id);
            int region = 0;
            const auto [end, ec] = std::from_chars(id.data(), id.data() + id.size(), region);
            if (ec != std::errc() || end != id.data() + id.size()) cx.fail(key, "region ids are integers, got \"" + id + "\"");
            // Unset fields come from the mesh file's material for the region, else "material".
            s.materials.by_region[region] = read_material(cx, m, key, s.materials.of(region));
            if (!present.count(region))
                sf.warnings.push_back(cx.source + ": \"" + key + "\": no tet of the mesh has region " + id);
        }
    }
    if (const json* x = find(root, "model"))
        s.model = get_enum<ModelKind>(cx, *x, "model", {{"fe", ModelKind::FE}, {"sn", ModelKind::SN}});
    if (const json* x = find(root, "method"))
        s.method = get_enum<Method>(cx, *x, "method", {{"edge", Method::Edge}, {"tet", Method::Tet}});
    if (const json* x = find(root, "gravity")) s.gravity = get_vec3(cx, *x, "gravity");
    if (const json* x = find(root, "damping")) {
        check_keys(cx, *x, "damping", {"alpha", "beta"});
        if (const json* a = find(*x, "alpha")) s.rayleigh_alpha = get_number(cx, *a, "damping.alpha", Range::NonNegative);
        if (const json* b = find(*x, "beta")) s.rayleigh_beta = get_number(cx, *b, "damping.beta", Range::NonNegative);
    }
    if (const json* x = find(root, "fixed")) s.fixed = select_vertices(cx, *x, "fixed", s.mesh, renumber);
    if (const json* x = find(root, "prescribed")) read_prescribed(cx, *x, renumber, s);
    if (const json* x = find(root, "load")) read_load(cx, *x, renumber, s);
    if (const json* x = find(root, "surface_loads")) read_surface_loads(cx, *x, s);
    if (const json* x = find(root, "initial")) read_initial(cx, *x, renumber, s);
    if (const json* x = find(root, "integrator"))
        s.integrator = get_enum<Integrator>(cx, *x, "integrator", integrator_names());
    if (const json* x = find(root, "newmark")) {
        check_keys(cx, *x, "newmark", {"beta", "gamma"});
        auto& ip = s.integrator_parameters;
        if (const json* b = find(*x, "beta")) ip.newmark_beta = get_number(cx, *b, "newmark.beta", Range::Positive);
        if (const json* g = find(*x, "gamma")) ip.newmark_gamma = get_number(cx, *g, "newmark.gamma", Range::Positive);
    }
    if (const json* x = find(root, "generalized_alpha")) {
        check_keys(cx, *x, "generalized_alpha", {"rho_inf"});
        if (const json* r = find(*x, "rho_inf"))
            s.integrator_parameters.rho_inf = get_number(cx, *r, "generalized_alpha.rho_inf", Range::NonNegative);
    }
    if (const json* x = find(root, "dt")) s.dt = get_number(cx, *x, "dt", Range::Positive);
    if (const json* x = find(root, "steps")) s.steps = get_int(cx, *x, "steps", 0);
    if (const json* x = find(root, "solver")) read_solver(cx, *x, s.solver);
    if (const json* x = find(root, "output")) read_output(cx, *x, sf.output);

    // What only the whole scene can tell (e.g. a vertex both fixed and prescribed).
    try {
        s.validate();
    } catch (const InvalidArgument& e) {
        std::string what = e.what();
        if (what.rfind("scene: ", 0) == 0) what.erase(0, 7);  // the file name says it
        throw InvalidArgument(cx.source + ": " + what);
    }
    return sf;
}

// ---- JSON text -------------------------------------------------------------

// Far deeper than any scene needs; deeper input is refused at parse time so
// that nothing later has to guard against deep recursion.
constexpr int kMaxDepth = 64;

// json::parse's DOM builder behind SAX events, so that nesting can be capped
// and every failure keeps its byte offset (nlohmann's number-overflow
// message has no position).
class CappedDomBuilder {
public:
    explicit CappedDomBuilder(json& root) : dom_(root, /*allow_exceptions=*/false) {}

    bool null() { return value() && dom_.null(); }
    bool boolean(bool v) { return value() && dom_.boolean(v); }
    bool number_integer(json::number_integer_t v) { return value() && dom_.number_integer(v); }
    bool number_unsigned(json::number_unsigned_t v) { return value() && dom_.number_unsigned(v); }
    bool number_float(json::number_float_t v, const std::string& s) { return value() && dom_.number_float(v, s); }
    bool string(json::string_t& v) { return value() && dom_.string(v); }
    bool binary(json::binary_t& v) { return value() && dom_.binary(v); }
    // A key given twice would silently keep one value ({"steps": 3, "steps": 5}).
    bool key(json::string_t& v) {
        Level& level = levels_.back();
        if (!level.keys.insert(v).second) {
            level.key = v;
            duplicate_ = path();
            return false;
        }
        level.key = v;
        return dom_.key(v);
    }
    bool start_object(std::size_t n) { return value() && enter(true) && dom_.start_object(n); }
    bool start_array(std::size_t n) { return value() && enter(false) && dom_.start_array(n); }
    bool end_object() { leave(); return dom_.end_object(); }
    bool end_array() { leave(); return dom_.end_array(); }
    template <class Exception>
    bool parse_error(std::size_t offset, const std::string& /*token*/, const Exception& e) {
        offset_ = offset;
        message_ = e.what();
        return false;
    }

    bool too_deep() const { return too_deep_; }
    // The key path of a duplicate key ("solver.cg_tolerance"), or "".
    const std::string& duplicate() const { return duplicate_; }
    std::size_t offset() const { return offset_; }
    const std::string& message() const { return message_; }

private:
    // An open object (its keys so far, the current one) or array (the
    // index of its next element).
    struct Level {
        bool object;
        std::set<std::string> keys;
        std::string key;
        std::size_t index = 0;
    };

    // A value starts: an array counts its elements.
    bool value() {
        if (!levels_.empty() && !levels_.back().object) ++levels_.back().index;
        return true;
    }
    bool enter(bool object) {
        too_deep_ = ++depth_ > kMaxDepth;
        if (!too_deep_) levels_.push_back({object, {}, {}, 0});
        return !too_deep_;
    }
    void leave() {
        --depth_;
        if (!levels_.empty()) levels_.pop_back();
    }
    std::string path() const {
        std::string out;
        for (const Level& l : levels_)
            out = l.object ? join(out, l.key) : item(out, l.index - 1);
        return out;
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    std::vector<Level> levels_;
    std::string duplicate_;
    int depth_ = 0;
    bool too_deep_ = false;
    std::size_t offset_ = 0;
    std::string message_;
};

// " at line L, column C" of a byte offset into `text`, counted as nlohmann does.
std::string position(const std::string& text, std::size_t offset) {
    offset = std::min(offset, text.size());
    std::size_t line = 1, line_start = 0;
    for (std::size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    return " at line " + std::to_string(line) + ", column " + std::to_string(offset - line_start);
}

json parse_json(const std::string& text, const std::string& source) {
    json root;
    CappedDomBuilder sax(root);
    if (json::sax_parse(text, &sax, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true))
        return root;
    if (sax.too_deep())
        throw InvalidArgument(source + ": invalid JSON: nested deeper than " + std::to_string(kMaxDepth) + " levels");
    if (!sax.duplicate().empty())
        throw InvalidArgument(printable(source) + ": \"" + printable(sax.duplicate()) + "\": duplicate key (each key may appear once)");
    // Drop nlohmann's "[json.exception.parse_error.101] " tag; its parse
    // errors say where they are, its other errors do not.
    std::string what = sax.message();
    if (const auto p = what.find("] "); what.rfind("[json.exception", 0) == 0 && p != std::string::npos) what.erase(0, p + 2);
    if (what.find(" at line ") == std::string::npos) what += position(text, sax.offset());
    throw InvalidArgument(source + ": invalid JSON: " + what);
}

}  // namespace

SceneFile parse_scene(const std::string& text, const std::string& base_dir, const std::string& source_name) {
    const Context cx{source_name, base_dir};
    const json root = parse_json(text, source_name);
    SceneFile sf = parse(cx, root);
    sf.path = source_name;
    return sf;
}

SceneFile load_scene(const std::string& path) {
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (fs::is_directory(status)) throw InvalidArgument(path + ": is a directory, not a scene file");
    // A device or a pipe (/dev/zero) may never end; the whole file is loaded.
    if (fs::exists(status) && !fs::is_regular_file(status)) throw InvalidArgument(path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InvalidArgument(path + ": cannot open scene file");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw InvalidArgument(path + ": error while reading the scene file");
    SceneFile sf = parse_scene(text.str(), fs::path(path).parent_path().string(), path);
    sf.path = path;
    return sf;
}

Scene default_scene() {
    Scene s;
    s.mesh = make_box(40, 10, 8, 0.005);
    s.materials = Material{1e6, 0.3, 1000};  // soft rubber; at 1e5 the beam folds and tets invert
    s.gravity = {0, 0, -9.81};
    double xmin = kInf;
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v) xmin = std::min(xmin, s.mesh.X[3 * std::size_t(v)]);
    s.fixed = select_in_box(s.mesh, {-kInf, -kInf, -kInf}, {xmin + 1e-9, kInf, kInf});
    s.integrator = Integrator::SemiImplicit;
    s.dt = 1e-3;
    s.steps = 1000;
    s.solver.cg_tolerance = 1e-6;
    return s;
}

SceneFile default_scene_file() {
    SceneFile sf;
    sf.scene = default_scene();
    sf.output.every = 20;
    return sf;
}

const char* to_string(OutputFormat format) {
    for (const auto& [name, f] : kOutputFormats)
        if (f == format) return name;
    return "";
}

const char* file_extension(OutputFormat format) {
    return format == OutputFormat::Ply ? ".ply" : format == OutputFormat::Obj ? ".obj" : ".vtu";
}

OutputFormat parse_output_format(const std::string& name, OutputMesh mesh, const std::string& what) {
    OutputFormat f{};
    if (const std::string error = output_format_error(name, mesh, f); !error.empty())
        throw InvalidArgument(printable(what) + ": " + error);
    return f;
}

}  // namespace edgefem
