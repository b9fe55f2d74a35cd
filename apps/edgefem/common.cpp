#include "common.hpp"

#include <cerrno>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "edgefem/core/coefficients.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/memory_estimate.hpp"
#include "edgefem/core/output_file.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"
#include "cpu/tet_kernels.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/parallel/adaptive_executor.hpp"
#include "edgefem/parallel/executors.hpp"

namespace edgefem::cli {

// ---- Mesh ---------------------------------------------------------------

void add_mesh_options(CLI::App& cmd, MeshOptions& opts) {
    cmd.add_option("MESH", opts.path,
                   "Mesh: a TetGen .node or .ele file or their common prefix, a Gmsh .msh, MEDIT .mesh "
                   "or Vega .veg file, or the built-in box:NXxNYxNZ (NX x NY x NZ cubes of 0.01 m, "
                   "6 tets each, at most 2^28 tets; box:10x5x4 is the paper's 1,200-tet box)")
        ->required()
        ->check(non_empty_path());
    cmd.add_flag("--fix-orientation", opts.fix_orientation,
                 "Reorient negatively oriented tets instead of rejecting the mesh");
    cmd.add_flag("--compact", opts.compact, "Remove vertices that no tet uses");
    add_ordering_option(cmd, opts.ordering);
}

void add_ordering_option(CLI::App& cmd, std::string& ordering) {
    cmd.add_option("--ordering", ordering,
                   "Renumber vertices for memory locality: input, random, rcm, morton, nd or metis "
                   "(docs/layouts.md; input and output stay in the mesh's numbering)")
        ->check(CLI::IsMember({"input", "random", "rcm", "morton", "nd", "metis"}))
        ->capture_default_str();
}

LoadedMesh load_mesh(const MeshOptions& opts) {
    LoadedMesh m;
    if (is_box_spec(opts.path))
        m.mesh = make_box_from_spec(opts.path);
    else
        m.mesh = read_mesh(opts.path, MeshFormat::Auto, &m.read);
    check_memory(opts.path, m.mesh.num_tets());
    if (!m.read.materials.empty())
        m.read.warnings.push_back(opts.path + ": the file's materials (" + std::to_string(m.read.materials.size()) +
                                  ") apply to scene files only (regions 1.." +
                                  std::to_string(m.read.materials.size()) + "); this command uses one material for every tet");
    ValidationOptions v;
    v.fix_orientation = opts.fix_orientation;
    // Higher-order tets keep their corners: their other nodes are dropped.
    v.compact_unreferenced = opts.compact || m.read.high_order_tets;
    v.fix_orientation_hint = "pass --fix-orientation";
    v.compact_hint = "pass --compact";
    m.validation = validate_mesh(m.mesh, v);
    if (const Ordering o = parse_ordering(opts.ordering); o != Ordering::Input) {
        m.new_of_old = vertex_ordering(m.mesh, o);
        m.user = std::move(m.mesh);
        m.mesh = permute_mesh(m.user, m.new_of_old);
    }
    return m;
}

std::vector<double> LoadedMesh::to_internal(const std::vector<double>& user_data) const {
    if (new_of_old.empty()) return user_data;
    std::vector<double> out(user_data.size());
    edgefem::to_internal<double>(user_data, out, new_of_old);
    return out;
}

std::vector<double> LoadedMesh::to_user(const std::vector<double>& internal_data) const {
    if (new_of_old.empty()) return internal_data;
    std::vector<double> out(internal_data.size());
    edgefem::to_user<double>(internal_data, out, new_of_old);
    return out;
}

std::vector<std::string> load_warnings(const LoadedMesh& m) {
    std::vector<std::string> w = m.read.warnings;
    w.insert(w.end(), m.validation.warnings.begin(), m.validation.warnings.end());
    return w;
}

// ---- Model --------------------------------------------------------------

void ModelOptions::validate() const {
    material.validate();
    if (precision_kind() == Precision::Float) {
        // The float kernels hold these, and their products with the mesh's
        // lengths, in float: its range (1.2e-38 to 3.4e38) ends long before
        // double's, and past it forces come out inf or NaN (Young's 1e38 did,
        // silently). Real materials lie well inside 1e-20 to 1e20.
        constexpr double lo = 1e-20, hi = 1e20;
        const auto check = [&](const std::string& what, double v) {
            if (v != 0 && !(std::abs(v) >= lo && std::abs(v) <= hi))
                throw InvalidArgument("--precision float: " + what + " " + fmt(v, 6) +
                                      " is outside the range float handles safely, 1e-20 to 1e20 in magnitude "
                                      "(use --precision double)");
        };
        check("Young's modulus (--young)", material.young);
        check("Lame's lambda (from --young and --poisson)", material.lambda());
        check("Lame's mu (from --young and --poisson)", material.mu());
        check("density (--density)", material.density);
    }
    if (method_kind() == Method::Tet && kind() == ModelKind::SN)
        throw InvalidArgument("--method tet supports only --model fe (the spring network is edge-based only)");
}

void check_mesh_scale(const Mesh& mesh, Precision precision, const std::string& path) {
    double lo[3], hi[3];
    for (int d = 0; d < 3; ++d) lo[d] = hi[d] = mesh.X.empty() ? 0.0 : mesh.X[d];
    for (std::size_t i = 0; i < mesh.X.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], mesh.X[i]);
        hi[i % 3] = std::max(hi[i % 3], mesh.X[i]);
    }
    const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    const bool single = precision == Precision::Float;
    // The kernels form volumes (size^3), their inverses and products with
    // the material: these bounds keep those inside the type's range with
    // margin (measured: a 2-tet mesh gives NaN or 0 in double below 1e-60
    // and above 1e80, in float below 1e-20 and above 1e10).
    const double min = single ? 1e-8 : 1e-30, max = single ? 1e8 : 1e30;
    if (!(size >= min && size <= max))
        throw InvalidArgument(path + ": the mesh's size (largest side of its bounding box: " + fmt(size, 3) +
                              " m) is outside what the " + (single ? "float" : "double") + " kernels handle, " +
                              (single ? "1e-8 to 1e8 m" : "1e-30 to 1e30 m") +
                              " (coordinates are in metres: rescale the mesh" +
                              (single ? ", or use --precision double)" : ")"));
}

void add_model_options(CLI::App& cmd, ModelOptions& opts, bool material_required) {
    cmd.add_option("--model", opts.model, "fe: the StVK tet element; sn: the nonlinear spring network")
        ->check(CLI::IsMember({"fe", "sn"}))
        ->capture_default_str();
    cmd.add_option("--method", opts.method, "edge: the edge-based kernels; tet: the conventional per-tet method (fe only)")
        ->check(CLI::IsMember({"edge", "tet"}))
        ->capture_default_str();
    cmd.add_option("--precision", opts.precision, "Scalar type of the kernels")
        ->check(CLI::IsMember({"double", "float"}))
        ->capture_default_str();
    cmd.add_option("--layout", opts.layout,
                   "Where the edge FE stiffness (and the forces of the serial and owner kernels) take their pair "
                   "terms from: tet-local (per-tet 6x6 form) or tsep-list (the mesh-wide TSEP list); results agree "
                   "to round-off")
        ->check(CLI::IsMember({"tet-local", "tsep-list"}))
        ->capture_default_str();
    auto* young = cmd.add_option("--young", opts.material.young, "Young's modulus (Pa)");
    auto* poisson = cmd.add_option("--poisson", opts.material.poisson, "Poisson ratio, in (-1, 0.5)");
    if (material_required) {
        young->required();
        poisson->required();
    } else {
        young->capture_default_str();
        poisson->capture_default_str();
    }
    cmd.add_option("--density", opts.material.density, "Density (kg/m^3)")->capture_default_str();
}

// ---- Execution ------------------------------------------------------------

void print_adaptive(const Executor& executor) {
    if (const auto* a = dynamic_cast<const AdaptiveExecutor*>(&executor)) print_kv("adaptive", a->summary());
}

void add_run_options(CLI::App& cmd, RunOptions& opts, bool with_variant) {
    cmd.add_option("--backend", opts.backend,
                   "Where the kernels run: auto (every core: the pool back-end, or serial on one core), serial "
                   "(the CPU back-end's loops on one thread), omp (OpenMP), tbb (oneTBB), pool (std::threads that "
                   "spin between calls: no system call per call), reference (plain loops, the tests' oracle; "
                   "slow) or cuda (the NVIDIA GPU back-end: simulate and static; an error where the build or "
                   "the machine has no CUDA) (docs/parallel.md, \"Back-ends\")")
        ->check(CLI::IsMember({"auto", "serial", "omp", "tbb", "pool", "reference", "cuda"}))
        ->capture_default_str();
    cmd.add_option("--threads", opts.threads, "Threads of the auto/omp/tbb/pool back-end (0: all hardware threads)")
        ->check(int_in_range(0))
        ->capture_default_str();
    cmd.add_option("--schedule", opts.schedule,
                   "How the omp/tbb/pool back-end hands the kernels' chunks to threads: dynamic (balances uneven "
                   "parts) or static (the same chunks to the same threads at every call, so each thread's "
                   "data stays in its cache). Results are identical; CG's vector passes and the owner K x "
                   "are always static (docs/parallel.md, \"Schedules\")")
        ->check(CLI::IsMember({"static", "dynamic"}))
        ->capture_default_str();
    auto* adaptive = cmd.add_option_function<std::string>(
                       "--adaptive", [&opts](const std::string& v) { opts.adaptive = v == "on"; },
                       "on: the first calls of every loop of the auto/omp/tbb/pool back-end are timed on the threads "
                       "and on one thread alternately, and all loops then run where they were faster in sum (small "
                       "meshes, where a barrier costs more than the work it splits, go serial; timed again after "
                       "2^14 calls, then 2^15, ...); off: every loop on the threads. Results are identical "
                       "(docs/parallel.md, \"The adaptive executor\")")
        ->check(CLI::IsMember({"on", "off"}));
    adaptive->default_str(opts.adaptive ? "on" : "off");
    if (with_variant)
        cmd.add_option("--variant", opts.variant,
                       "How concurrent writes are resolved: auto (owner when the vertex numbering has "
                       "locality, else gather), colour (coloured scatter, deterministic), gather "
                       "(pull through adjacency lists, deterministic), atomic (atomic adds), private "
                       "(per-thread accumulators + reduction) or owner (fixed parts of consecutive items, "
                       "writes past a part spilled and added in part order, deterministic)")
            ->check(CLI::IsMember({"auto", "colour", "color", "gather", "atomic", "private", "owner"}))
            ->capture_default_str();
}


// ---- Text I/O -------------------------------------------------------------

namespace {

std::string where(const std::string& path, std::int64_t line) {
    return line > 0 ? path + ":" + std::to_string(line) + ": " : path + ": ";
}

// One number token; from_chars does not take a leading '+'.
bool parse_double(std::string_view tok, double& out) {
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), out);
    return ec == std::errc() && end == tok.data() + tok.size();
}

}  // namespace

std::vector<double> read_vectors(const std::string& path, index_t count) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open file: " + std::strerror(errno));
    std::vector<double> v;
    v.reserve(3 * std::size_t(count));
    std::string text;
    std::int64_t line = 0;
    while (std::getline(in, text)) {
        ++line;
        std::istringstream tokens(text);
        std::vector<std::string> tok;
        for (std::string t; tokens >> t;) tok.push_back(t);
        if (tok.empty()) continue;  // blank line
        if (v.size() == 3 * std::size_t(count))
            throw Error(where(path, line) + "more lines than the mesh's " + std::to_string(count) + " vertices");
        if (tok.size() != 3)
            throw Error(where(path, line) + "expected 3 numbers 'x y z', found " + std::to_string(tok.size()) +
                        " fields");
        for (const auto& t : tok) {
            double x;
            if (!parse_double(t, x)) throw Error(where(path, line) + "not a number: '" + t + "'");
            if (!std::isfinite(x)) throw Error(where(path, line) + "non-finite value: '" + t + "'");
            v.push_back(x);
        }
    }
    if (in.bad()) throw Error(path + ": read error");
    if (v.size() != 3 * std::size_t(count))
        throw Error(where(path, line) + "file ends after " + std::to_string(v.size() / 3) + " lines, expected " +
                    std::to_string(count) + " (one per vertex)");
    return v;
}

namespace {

// %.17g (exact) lines through an OutputFile: written whole or not at all;
// throws IoError naming the file on any failure.
void write_lines(const std::string& path, const double* v, std::size_t n, std::size_t per_line) {
    OutputFile f(path);
    char line[96];
    for (std::size_t i = 0; i + per_line <= n; i += per_line) {
        const int len = per_line == 3 ? std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", v[i], v[i + 1], v[i + 2])
                                      : std::snprintf(line, sizeof line, "%.17g\n", v[i]);
        f.write(std::string_view(line, static_cast<std::size_t>(len)));
    }
    f.commit();
}

}  // namespace

void write_vectors(const std::string& path, const std::vector<double>& v) { write_lines(path, v.data(), v.size(), 3); }

void write_scalar(const std::string& path, double value) { write_lines(path, &value, 1, 1); }

std::string fmt(double value, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    return buf;
}

void print_kv(const std::string& key, const std::string& value) { std::printf("%s: %s\n", key.c_str(), value.c_str()); }

void print_kv(const std::string& key, double value) { print_kv(key, fmt(value)); }

}  // namespace edgefem::cli
