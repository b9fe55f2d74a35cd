// `edgefem bench-layouts MESH`: the memory-layout comparison
// (docs/layouts.md, "Storage layouts"). One table row per ordering x layout x
// back-end x threads with the median ns per tet of the force kernel, the
// stiffness K, K x and a whole semi-implicit step, the bytes of precomputed
// data per tet and, with --cachegrind, the D1 and last-level data-cache
// misses per tet of the force kernel.
//
// Layouts: tet-local and tsep-list are the two edge FE stiffness layouts
// behind make_evaluator (forces, K, K x, step; any back-end); the eight
// <aos|soa>-<double|float>-<split|packed> are the force-only layouts of
// layout_kernels.hpp (serial, force column only).
//
// --cachegrind re-runs this program under
// `valgrind --tool=cachegrind --cache-sim=yes` once per ordering (a hidden
// child mode that calls each force kernel once untimed, then N times inside
// a function of its own), and reads the misses of those functions from
// cachegrind's output file: the whole-run summary lines are dominated by
// reading the mesh and building the models, which no per-call figure could
// subtract without a second valgrind run per layout.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "common.hpp"
#include "lab/benchmark_scene.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/edge_kernels.hpp"
#include "edgefem/core/error.hpp"
#include "lab/layout_kernels.hpp"
#include "edgefem/core/simulator.hpp"
#include "cpu/tet_edge_form.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"
#include "timing.hpp"

extern char** environ;

namespace edgefem::cli {

namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
const std::vector<std::string> kOperatorLayouts = {"tet-local", "tsep-list"};
// The cachegrind id of the force kernel the operator layouts run
// (edge_forces on EdgeModel); the force layouts are 0..7.
constexpr int kEdgeModelId = 8;

std::vector<std::string> force_layout_names() {
    std::vector<std::string> names;
    for_each_force_layout([&]<class L>(L) { names.push_back(L::name()); });
    return names;
}

std::vector<std::string> all_layout_names() {
    std::vector<std::string> names = kOperatorLayouts;
    for (const auto& n : force_layout_names()) names.push_back(n);
    return names;
}

// Position of a force layout in for_each_force_layout's order.
template <class L>
constexpr int layout_id() {
    return (L::vec == VecLayout::SoA ? 2 : 0) + (sizeof(typename L::scalar) == 4 ? 4 : 0) +
           (L::tsep == TsepLayout::Packed ? 1 : 0);
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
}

struct Options {
    MeshOptions mesh;
    std::vector<std::string> orderings;  // empty: {mesh.ordering}
    std::vector<std::string> layouts;    // empty: all
    std::vector<std::string> backends = {"serial"};
    std::vector<int> threads = {0};
    std::string variant = "auto";
    std::string precision = "double";
    double seconds = 0.5;
    bool quick = false;
    bool cachegrind = false;
    int cachegrind_calls = 3;
    bool cachegrind_child = false;  // internal: the run under valgrind
};

struct Timer {
    double seconds;
    std::size_t min_calls;
    template <class Call>
    double ns_per_tet(Call&& call, index_t tets) const {
        return median_of_sorted(time_calls(seconds, call, min_calls)) / double(tets);
    }
};

struct Row {
    std::string ordering, layout, backend;
    int threads = 1;
    double force = kNone, K = kNone, Kx = kNone, step = kNone, bytes = kNone, d1 = kNone, ll = kNone;
};

// ---- Table ------------------------------------------------------------------

void print_table_header(bool cachegrind) {
    std::printf("%-8s %-17s %-8s %7s %9s %9s %9s %10s %10s", "ordering", "layout", "backend", "threads", "force", "K",
                "Kx", "step", "bytes/tet");
    if (cachegrind) std::printf(" %9s %9s", "D1/tet", "LL/tet");
    std::printf("\n");
    std::fflush(stdout);
}

std::string cell(double v, int decimals) {
    if (std::isnan(v)) return "-";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

void print_row(const Row& r, bool cachegrind) {
    std::printf("%-8s %-17s %-8s %7d %9s %9s %9s %10s %10s", r.ordering.c_str(), r.layout.c_str(), r.backend.c_str(),
                r.threads, cell(r.force, 1).c_str(), cell(r.K, 1).c_str(), cell(r.Kx, 1).c_str(), cell(r.step, 1).c_str(),
                cell(r.bytes, 1).c_str());
    if (cachegrind) std::printf(" %9s %9s", cell(r.d1, 2).c_str(), cell(r.ll, 2).c_str());
    std::printf("\n");
    std::fflush(stdout);
}

// ---- Measurements ---------------------------------------------------------------

// Precomputed data per tet of the edge model an operator holds in `layout`
// (elastic_operator.cpp: tet-local drops the TSEP targets and adds the form).
template <class S>
double operator_bytes(const Mesh& mesh, const Topology& topo, const EdgeModel<double>& md, const std::string& layout) {
    const EdgeModel<S> m = convert_scalar<S>(md);
    if (layout == "tsep-list") return m.bytes_per_tet(true);
    return m.bytes_per_tet(false) + make_tet_edge_form<S>(mesh, topo, Materials(Material{})).bytes_per_tet();
}

template <class S>
double step_ns_per_tet(const Mesh& mesh, const ModelOptions& model, const ExecOptions& exec, const Timer& t) {
    const auto ex = exec.executor();
    Simulator<S> sim(step_benchmark_scene(mesh, model.material), ex, operator_factory<S>(exec, ex, model.layout_kind()));
    return t.ns_per_tet([&] { sim.step(); }, mesh.num_tets());
}

void measure_operator(const Mesh& mesh, const ModelOptions& model, const ExecOptions& exec, const Timer& t, Row& row) {
    const index_t tets = mesh.num_tets();
    auto eval = make_evaluator(mesh, model, exec);
    eval->set_displacement(deformation_displacement(mesh, Deformation::Twist));
    const std::vector<double> x = deformation_displacement(mesh, Deformation::Random);  // kx: a generic vector
    double* out[3] = {&row.force, &row.K, &row.Kx};
    const Kernel kernels[3] = {Kernel::Force, Kernel::Stiffness, Kernel::Kx};
    for (int k = 0; k < 3; ++k) {
        eval->prepare(kernels[k], x);
        *out[k] = t.ns_per_tet(
            [&] {
                eval->run(kernels[k]);
                eval->consume();
            },
            tets);
    }
    eval.reset();
    row.step = model.precision_kind() == Precision::Float ? step_ns_per_tet<float>(mesh, model, exec, t)
                                                          : step_ns_per_tet<double>(mesh, model, exec, t);
}

template <class L>
void measure_force_layout(const EdgeModel<double>& md, const std::vector<double>& u, const Timer& t, Row& row) {
    using S = typename L::scalar;
    const typename L::Model m = make_layout_model<L::vec, S, L::tsep>(md);
    const typename L::Vectors ul = to_vec3_array<L::vec, S>(u.data(), md.num_vertices);
    typename L::Vectors f;
    typename L::State st;
    row.force = t.ns_per_tet(
        [&] {
            layout_forces(m, ul, f, st);
            escape(f.data.data());
        },
        md.num_tets);
    row.bytes = m.bytes_per_tet();
}

// ---- Cachegrind -----------------------------------------------------------------

// The measured calls of kernel `Id`, in a function of their own (everything
// inlined into it) so that cachegrind's per-function counts isolate them.
template <int Id, class Call>
[[gnu::noinline, gnu::flatten]] void cg_measured(Call& call, int calls) {
    for (int i = 0; i < calls; ++i) call();
}
template <int Id, class Call>
[[gnu::noinline]] void cg_warmup(Call& call) {
    call();
}

// The child run under valgrind: each selected force kernel once untimed
// (cold misses), then `calls` times in cg_measured<id>.
void cachegrind_child(const Options& opts) {
    const LoadedMesh lm = load_mesh(opts.mesh);
    const Mesh& mesh = lm.mesh;
    const Topology topo = build_topology(mesh);
    const EdgeModel<double> md = make_edge_model<double>(topo, compute_coefficients(mesh, topo, Materials(Material{})));
    const std::vector<double> u = deformation_displacement(mesh, Deformation::Twist);
    const int calls = opts.cachegrind_calls;
    for_each_force_layout([&]<class L>(L) {
        if (!contains(opts.layouts, L::name())) return;
        using S = typename L::scalar;
        const typename L::Model m = make_layout_model<L::vec, S, L::tsep>(md);
        const typename L::Vectors ul = to_vec3_array<L::vec, S>(u.data(), md.num_vertices);
        typename L::Vectors f;
        typename L::State st;
        auto call = [&] {
            layout_forces(m, ul, f, st);
            escape(f.data.data());
        };
        cg_warmup<layout_id<L>()>(call);
        cg_measured<layout_id<L>()>(call, calls);
    });
    if (contains(opts.layouts, "tet-local") || contains(opts.layouts, "tsep-list")) {
        std::vector<double> f(u.size());
        EdgeState<double> st;
        auto call = [&] {
            edge_forces<ModelKind::FE, false>(md, u.data(), f.data(), st);
            escape(f.data());
        };
        cg_warmup<kEdgeModelId>(call);
        cg_measured<kEdgeModelId>(call, calls);
    }
    std::printf("cachegrind-child: done\n");
}

std::string find_in_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "/usr/bin:/bin");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        const std::string p = (dir.empty() ? "." : dir) + "/" + name;
        if (::access(p.c_str(), X_OK) == 0) return p;
    }
    return "";
}

// Cachegrind's --D1 / --LL value "size,assoc,line" for the level-1 data
// cache and the last level, from Linux's sysfs (cachegrind's own CPUID
// detection misreads some virtual machines: 256 MiB direct-mapped LL here).
// Empty when sysfs does not say or cachegrind could not model it (the number
// of sets must be a power of two).
struct CacheSpec {
    std::string d1, ll;
};

CacheSpec sysfs_caches() {
    CacheSpec spec;
    int ll_level = 0;
    for (int i = 0; i < 16; ++i) {
        const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/";
        auto read = [&](const char* name) {
            std::ifstream in(dir + name);
            std::string v;
            in >> v;
            return v;
        };
        const std::string level = read("level"), type = read("type"), size = read("size");
        const std::string ways = read("ways_of_associativity"), line = read("coherency_line_size");
        if (level.empty() || size.empty() || ways.empty() || line.empty()) continue;
        long bytes = std::atol(size.c_str());
        if (size.back() == 'K') bytes *= 1024;
        if (size.back() == 'M') bytes *= 1024 * 1024;
        const long w = std::atol(ways.c_str()), l = std::atol(line.c_str());
        if (bytes <= 0 || w <= 0 || l <= 0 || bytes % (w * l) != 0) continue;
        const long sets = bytes / (w * l);
        if ((sets & (sets - 1)) != 0) continue;
        const std::string value = std::to_string(bytes) + "," + std::to_string(w) + "," + std::to_string(l);
        const int lv = std::atoi(level.c_str());
        if (lv == 1 && type == "Data") spec.d1 = value;
        if (lv > 1 && type == "Unified" && lv > ll_level) {
            ll_level = lv;
            spec.ll = value;
        }
    }
    return spec;
}

std::string self_exe() {
    char buf[4096];
    const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (n <= 0) throw Error("--cachegrind: cannot find this program's path (/proc/self/exe)");
    return std::string(buf, std::size_t(n));
}

std::string make_temp(const std::string& stem) {
    const char* dir = std::getenv("TMPDIR");
    std::string path = std::string(dir && *dir ? dir : "/tmp") + "/" + stem + "XXXXXX";
    std::vector<char> buf(path.begin(), path.end());
    buf.push_back('\0');
    const int fd = ::mkstemp(buf.data());
    if (fd < 0) throw Error("--cachegrind: cannot create a temporary file in " + std::string(dir && *dir ? dir : "/tmp"));
    ::close(fd);
    return buf.data();
}

std::string last_line(const std::string& path) {
    std::ifstream in(path);
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty()) last = line;
    return last;
}

// Misses per tet of each kernel id, and the simulated caches.
struct CachegrindResult {
    std::map<int, std::pair<double, double>> misses;  // id -> (D1, LL) per tet per call
    std::vector<std::string> caches;                   // "D1 cache: ..." lines
};

// Sums the counts of every cg_measured<id, ...> function in a cachegrind
// output file (events Ir I1mr ILmr Dr D1mr DLmr Dw D1mw DLmw).
CachegrindResult parse_cachegrind(const std::string& path, double per) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot read cachegrind output");
    std::vector<std::string> events;
    std::map<int, std::vector<double>> sums;
    CachegrindResult r;
    int current = -1;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("desc: ", 0) == 0) {
            if (line.find("D1 cache") != std::string::npos || line.find("LL cache") != std::string::npos)
                r.caches.push_back(line.substr(6));
        } else if (line.rfind("events: ", 0) == 0) {
            std::istringstream s(line.substr(8));
            for (std::string e; s >> e;) events.push_back(e);
        } else if (line.rfind("fn=", 0) == 0) {
            current = -1;
            const auto at = line.find("cg_measured<");
            if (at != std::string::npos) current = std::atoi(line.c_str() + at + 12);
        } else if (current >= 0 && !line.empty() && std::isdigit(static_cast<unsigned char>(line[0]))) {
            std::istringstream s(line);
            std::string lineno;
            s >> lineno;
            auto& v = sums[current];
            v.resize(events.size(), 0.0);
            double x;
            for (std::size_t k = 0; k < events.size() && s >> x; ++k) v[k] += x;
        }
    }
    auto column = [&](const std::string& name) -> int {
        const auto it = std::find(events.begin(), events.end(), name);
        if (it == events.end()) throw Error(path + ": no '" + name + "' event (was --cache-sim=yes given?)");
        return int(it - events.begin());
    };
    const int d1r = column("D1mr"), d1w = column("D1mw"), llr = column("DLmr"), llw = column("DLmw");
    for (const auto& [id, v] : sums) r.misses[id] = {(v[d1r] + v[d1w]) / per, (v[llr] + v[llw]) / per};
    return r;
}

// Runs the child under cachegrind for one ordering; throws Error on failure.
CachegrindResult run_cachegrind(const std::string& valgrind, const Options& opts, const std::string& ordering,
                                const std::vector<std::string>& layouts, index_t tets) {
    const std::string out = make_temp("edgefem-cachegrind-"), log = make_temp("edgefem-cachegrind-log-");
    std::string layout_list;
    for (const auto& l : layouts) layout_list += (layout_list.empty() ? "" : ",") + l;
    std::vector<std::string> args = {valgrind, "--tool=cachegrind", "--cache-sim=yes", "--cachegrind-out-file=" + out};
    const CacheSpec caches = sysfs_caches();
    if (!caches.d1.empty()) args.push_back("--D1=" + caches.d1);
    if (!caches.ll.empty()) args.push_back("--LL=" + caches.ll);
    const std::vector<std::string> child = {self_exe(), "bench-layouts", opts.mesh.path, "--ordering", ordering,
                                            "--layouts", layout_list, "--cachegrind-calls",
                                            std::to_string(opts.cachegrind_calls), "--cachegrind-child"};
    args.insert(args.end(), child.begin(), child.end());
    if (opts.mesh.fix_orientation) args.push_back("--fix-orientation");
    if (opts.mesh.compact) args.push_back("--compact");
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_TRUNC, 0);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, valgrind.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        std::remove(out.c_str());
        std::remove(log.c_str());
        throw Error("--cachegrind: cannot run " + valgrind);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        const std::string why = last_line(log);
        std::remove(out.c_str());
        std::remove(log.c_str());
        throw Error("--cachegrind: the run under valgrind failed: " + why);
    }
    CachegrindResult r = parse_cachegrind(out, double(opts.cachegrind_calls) * double(tets));
    std::remove(out.c_str());
    std::remove(log.c_str());
    return r;
}

// ---- The command ----------------------------------------------------------------

void run_bench_layouts(Options opts) {
    if (opts.orderings.empty()) opts.orderings = {opts.mesh.ordering};
    if (opts.layouts.empty()) opts.layouts = all_layout_names();
    if (opts.cachegrind_child) {
        cachegrind_child(opts);
        return;
    }
    const Timer timer{opts.quick ? 0.05 : opts.seconds, std::size_t(opts.quick ? 3 : 5)};

    MeshOptions read = opts.mesh;
    read.ordering = "input";
    LoadedMesh lm = load_mesh(read);
    for (const auto& w : load_warnings(lm)) std::fprintf(stderr, "edgefem: warning: %s\n", w.c_str());
    const Mesh& user = lm.mesh;

    std::string valgrind;
    if (opts.cachegrind) {
        valgrind = find_in_path("valgrind");
        if (valgrind.empty()) {
            std::printf("cachegrind: skipped: valgrind not found on PATH (install valgrind for the D1/LL columns)\n");
            opts.cachegrind = false;
        }
    }
    const bool serial = contains(opts.backends, "serial");
    std::vector<std::string> force_layouts, operator_layouts;
    for (const auto& l : opts.layouts) (contains(kOperatorLayouts, l) ? operator_layouts : force_layouts).push_back(l);

    print_kv("mesh", opts.mesh.path);
    print_kv("vertices", user.num_vertices());
    print_kv("tets", user.num_tets());
    print_kv("precision", opts.precision + " (tet-local, tsep-list; the force layouts name their own)");
    print_kv("configuration", "twist (K x: a random vector); step: semi-implicit, dt = 1 ms, 20 CG iterations");
    print_kv("timing", "median ns per tet of calls over " + fmt(timer.seconds, 3) + " s (at least " +
                           std::to_string(timer.min_calls) + " calls) after a warm-up");
    if (!serial && !force_layouts.empty())
        std::printf("note: the force layouts run serial only: add serial to --backend to time them\n");
    if (opts.cachegrind)
        print_kv("cachegrind", "data misses (read + write) per tet of the force kernel, mean of " +
                                   std::to_string(opts.cachegrind_calls) + " calls after a warm-up call");

    bool header = false;
    for (const std::string& ordering : opts.orderings) {
        Mesh mesh = ordering == "input" ? user : permute_mesh(user, vertex_ordering(user, parse_ordering(ordering)));
        const Topology topo = build_topology(mesh);
        const EdgeModel<double> md = make_edge_model<double>(topo, compute_coefficients(mesh, topo, Materials(Material{})));
        const std::vector<double> u = deformation_displacement(mesh, Deformation::Twist);

        CachegrindResult cg;
        if (opts.cachegrind && serial) cg = run_cachegrind(valgrind, opts, ordering, opts.layouts, mesh.num_tets());
        if (!header) {
            for (const auto& c : cg.caches) print_kv("cachegrind_cache", c);
            std::printf("\n");
            print_table_header(opts.cachegrind);
            header = true;
        }
        auto set_misses = [&](Row& row, int id) {
            if (const auto it = cg.misses.find(id); it != cg.misses.end()) {
                row.d1 = it->second.first;
                row.ll = it->second.second;
            }
        };

        for (const std::string& backend : opts.backends) {
            std::vector<int> thread_counts = opts.threads;
            if (backend == "serial") thread_counts = {1};
            for (int threads : thread_counts) {
                ExecOptions exec;
                exec.backend = backend;
                exec.threads = threads;
                exec.variant = opts.variant;
                exec.variant_given = backend != "serial";
                const int actual_threads = backend == "serial" ? 1 : exec.executor()->threads();
                for (const std::string& layout : operator_layouts) {
                    ModelOptions model;
                    model.layout = layout;
                    model.precision = opts.precision;
                    Row row{ordering, layout, backend, actual_threads};
                    measure_operator(mesh, model, exec, timer, row);
                    row.bytes = model.precision_kind() == Precision::Float ? operator_bytes<float>(mesh, topo, md, layout)
                                                                           : operator_bytes<double>(mesh, topo, md, layout);
                    if (backend == "serial") set_misses(row, kEdgeModelId);
                    print_row(row, opts.cachegrind);
                }
                if (backend != "serial") continue;
                for_each_force_layout([&]<class L>(L) {
                    if (!contains(force_layouts, L::name())) return;
                    Row row{ordering, L::name(), backend, 1};
                    measure_force_layout<L>(md, u, timer, row);
                    set_misses(row, layout_id<L>());
                    print_row(row, opts.cachegrind);
                });
            }
        }
    }
}

}  // namespace

void add_bench_layouts_command(CLI::App& app) {
    auto opts = std::make_shared<Options>();
    auto* cmd = app.add_subcommand(
        "bench-layouts",
        "Compare memory layouts: a table of ordering x layout x back-end x threads with the median ns per tet of the "
        "force kernel, the stiffness K, K x and a semi-implicit step, the bytes of precomputed data per tet and, "
        "with --cachegrind, D1 and last-level data-cache misses per tet of the force kernel (docs/layouts.md)");
    add_mesh_options(*cmd, opts->mesh);
    auto* ordering = cmd->get_option("--ordering");
    cmd->add_option("--orderings", opts->orderings, "Comma-separated vertex orderings, one block of rows each")
        ->delimiter(',')
        ->check(CLI::IsMember({"input", "random", "rcm", "morton", "nd", "metis"}))
        ->excludes(ordering);
    const auto names = all_layout_names();
    cmd->add_option("--layouts", opts->layouts,
                    "Comma-separated layouts (default: all): tet-local and tsep-list are the edge FE stiffness "
                    "layouts (force, K, K x, step on any back-end); <aos|soa>-<double|float>-<split|packed> are "
                    "the force-kernel storage layouts (serial, force only)")
        ->delimiter(',')
        ->check(CLI::IsMember(names));
    cmd->add_option("--backend", opts->backends, "Comma-separated back-ends: serial, omp, tbb, pool")
        ->delimiter(',')
        ->check(CLI::IsMember({"serial", "omp", "tbb", "pool"}))
        ->capture_default_str();
    cmd->add_option("--threads", opts->threads, "Comma-separated thread counts of omp/tbb/pool (0: all hardware threads)")
        ->delimiter(',')
        ->check(CLI::Range(0, 4096))
        ->capture_default_str();
    cmd->add_option("--variant", opts->variant, "Parallel variant of omp/tbb/pool rows (see `edgefem bench --help`)")
        ->check(CLI::IsMember({"auto", "colour", "color", "gather", "atomic", "private", "owner"}))
        ->capture_default_str();
    cmd->add_option("--precision", opts->precision, "Scalar type of the tet-local and tsep-list rows")
        ->check(CLI::IsMember({"double", "float"}))
        ->capture_default_str();
    cmd->add_option("--seconds", opts->seconds,
                    "Time budget of each measurement's timed calls, at most 3600 (and at most 2^22 calls)")
        ->check(seconds_at_most(3600))
        ->capture_default_str();
    cmd->add_flag("--quick", opts->quick, "0.05 s and at least 3 calls per measurement");
    cmd->add_flag("--cachegrind", opts->cachegrind,
                  "Add D1 and LL data-cache misses per tet of the force kernel, from a run of this program under "
                  "valgrind --tool=cachegrind --cache-sim=yes per ordering (skipped with a message without valgrind)");
    cmd->add_option("--cachegrind-calls", opts->cachegrind_calls, "Force calls measured under cachegrind per layout (1 to 1000)")
        ->check(int_in_range(1, 1000))
        ->capture_default_str();
    cmd->add_flag("--cachegrind-child", opts->cachegrind_child)->group("");  // internal
    cmd->callback([opts] { run_bench_layouts(*opts); });
}

}  // namespace edgefem::cli
