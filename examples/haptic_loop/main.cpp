// edgefem_haptic_loop: a fixed-rate (default 1 kHz) loop stepping a soft
// armadillo (../shared/meshes/armadillo-7k, else a generated box of ~7.5k
// tets) glued at its base, while a probe circles around it and pushes on the
// surface vertices nearest to it: the external force moves every tick, as a
// haptic device would drive it. Each tick runs one semi-implicit step with a
// fixed CG budget (scene.solver.cg_fixed_iterations), then sleeps until the
// next tick. A step that ends after its tick's deadline is a missed
// deadline; when the loop falls behind it skips the ticks already past
// (they are counted as dropped) instead of running a backlog.
//
//   edgefem_haptic_loop [--mesh PATH|box:NXxNYxNZ] [--seconds S] [--rate HZ]
//       [--cg-iters N] [--stiffness-interval N] [--precision double|float] [--model fe|sn]
//       [--backend serial|omp|tbb] [--threads N] [--variant V] [--force NEWTONS]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/validate_mesh.hpp"
#ifdef EDGEFEM_HAPTIC_HAVE_PARALLEL
#include "edgefem/parallel/executors.hpp"
#include "edgefem/parallel/async_tangent.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#endif
#ifdef EDGEFEM_HAPTIC_HAVE_PARTITION
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"
#endif

#ifndef EDGEFEM_SHARED_MESHES
#define EDGEFEM_SHARED_MESHES "../shared/meshes"
#endif

using namespace edgefem;
using clock_type = std::chrono::steady_clock;

namespace {

struct Options {
    std::string mesh;  // "" = armadillo-7k or its stand-in
    double seconds = 5;
    double rate = 1000;
    int cg_iters = 3;
    std::string precision = "double";
    std::string model = "fe";
    int stiffness_interval = 1;  // build K every N steps (a lagged tangent)
    // Build K on a background thread (the second core), swap it in when
    // ready: the default where the parallel module is built, because only
    // then does the FE loop keep up (examples/haptic_loop/README.md).
#ifdef EDGEFEM_HAPTIC_HAVE_PARALLEL
    bool async_tangent = true;
#else
    bool async_tangent = false;
#endif
    std::string backend = "serial";
    int threads = 0;
    std::string variant = "auto";
    std::string ordering = "rcm";
    int spin_us = 150;  // spin (instead of sleeping) this long before each tick
    double force = 0.2;  // N, spread over the probed vertices
    int probe_vertices = 6;
    double young = 1e6, poisson = 0.4, density = 1000;
    double alpha = 2.0;      // Rayleigh mass damping (1/s)
    bool definite = true;    // clamp g(E) >= 0 inside K: K stays positive semi-definite
    double gravity = 9.81;   // m/s^2, along -up
    bool free_run = false;   // no clock: every tick is stepped, as fast as possible
};

const char* const kUsage =
    "usage: edgefem_haptic_loop [--mesh PATH|box:NXxNYxNZ] [--seconds S] "
    "[--rate HZ] [--cg-iters N] [--stiffness-interval N] [--async-tangent|--sync-tangent] [--precision double|float] [--model fe|sn] "
    "[--backend serial|omp|tbb] [--threads N] [--variant auto|colour|gather|atomic|private|owner] [--ordering input|rcm] [--spin-us US] [--force N] [--young PA] [--alpha 1/S] [--indefinite] [--free-run] [--gravity G]\n";

// A bad argument: the message and the usage line on stderr, exit code 2.
[[noreturn]] void usage(const char* msg) {
    std::fprintf(stderr, "edgefem_haptic_loop: %s\n%s", msg, kUsage);
    std::exit(2);
}

// --help: what the loop does and its flags on stdout, exit code 0.
[[noreturn]] void help() {
    const Options d;
    std::printf(
        "edgefem_haptic_loop: a fixed-rate loop stepping a soft armadillo (or a generated box) while a probe\n"
        "circles it and pushes on the surface vertices nearest to it; one semi-implicit step per tick with a\n"
        "fixed CG budget. Reports missed deadlines, dropped ticks and the step-time distribution\n"
        "(examples/haptic_loop/README.md).\n\n%s\n"
        "  --mesh PATH|box:NXxNYxNZ   mesh file or generated box (default: armadillo-7k from\n"
        "                             $EDGEFEM_MESH_DIR or ../shared/meshes, else a box of ~7.5k tets)\n"
        "  --seconds S                wall-clock seconds to run (default %g)\n"
        "  --rate HZ                  ticks per second; dt = 1 / rate (default %g)\n"
        "  --cg-iters N               fixed CG iterations per step, 0: CG to tolerance (default %d)\n"
        "  --stiffness-interval N     build K every N steps (default %d)\n"
        "  --async-tangent            build K on a background thread (the default where the parallel module is built)\n"
        "  --sync-tangent             build K on the loop's thread\n"
        "  --precision double|float   scalar type (default %s)\n"
        "  --model fe|sn              finite elements or the spring network (default %s)\n"
        "  --backend serial|omp|tbb   back-end of the kernels (default %s)\n"
        "  --threads N                threads of omp/tbb, 0: all hardware threads (default %d)\n"
        "  --variant V                parallel variant: auto, colour, gather, atomic, private, owner (default %s)\n"
        "  --ordering input|rcm       vertex numbering used inside the loop (default %s)\n"
        "  --spin-us US               spin instead of sleeping this long before each tick (default %d)\n"
        "  --force N                  probe force in newtons, spread over its vertices (default %g)\n"
        "  --young PA                 Young's modulus (default %g)\n"
        "  --alpha 1/S                Rayleigh mass damping (default %g)\n"
        "  --indefinite               do not clamp g(E) >= 0 inside K\n"
        "  --free-run                 no clock: step every tick as fast as possible\n"
        "  --gravity G                gravity in m/s^2 along -up (default %g)\n"
        "  -h, --help                 print this help and exit\n",
        kUsage, d.seconds, d.rate, d.cg_iters, d.stiffness_interval, d.precision.c_str(), d.model.c_str(),
        d.backend.c_str(), d.threads, d.variant.c_str(), d.ordering.c_str(), d.spin_us, d.force, d.young, d.alpha,
        d.gravity);
    std::exit(0);
}

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) usage(("missing value for " + a).c_str());
            return argv[++i];
        };
        if (a == "--mesh") o.mesh = next();
        else if (a == "--seconds") o.seconds = std::atof(next().c_str());
        else if (a == "--rate") o.rate = std::atof(next().c_str());
        else if (a == "--cg-iters") o.cg_iters = std::atoi(next().c_str());
        else if (a == "--precision") o.precision = next();
        else if (a == "--model") o.model = next();
        else if (a == "--stiffness-interval") o.stiffness_interval = std::atoi(next().c_str());
        else if (a == "--async-tangent") o.async_tangent = true;
        else if (a == "--sync-tangent") o.async_tangent = false;
        else if (a == "--backend") o.backend = next();
        else if (a == "--threads") o.threads = std::atoi(next().c_str());
        else if (a == "--variant") o.variant = next();
        else if (a == "--ordering") o.ordering = next();
        else if (a == "--spin-us") o.spin_us = std::max(0, std::atoi(next().c_str()));
        else if (a == "--force") o.force = std::atof(next().c_str());
        else if (a == "--young") o.young = std::atof(next().c_str());
        else if (a == "--alpha") o.alpha = std::atof(next().c_str());
        else if (a == "--indefinite") o.definite = false;
        else if (a == "--free-run") o.free_run = true;
        else if (a == "--gravity") o.gravity = std::atof(next().c_str());
        else if (a == "-h" || a == "--help") help();
        else usage(("unknown argument " + a).c_str());
    }
    if (!(o.seconds > 0) || !(o.rate > 0) || o.cg_iters < 0) usage("need --seconds > 0, --rate > 0, --cg-iters >= 0 (0: CG to tolerance)");
    if (o.precision != "double" && o.precision != "float") usage("--precision is double or float");
    if (o.model != "fe" && o.model != "sn") usage("--model is fe or sn");
    return o;
}

// The mesh and its "up" axis (1 for the y-up Stanford meshes, 2 for a box).
Mesh load(const Options& o, std::string& origin, int& up) {
    std::string path = o.mesh;
    if (path.empty()) {
        const std::string shared = std::string(EDGEFEM_SHARED_MESHES) + "/armadillo-7k";
        const char* dir = std::getenv("EDGEFEM_MESH_DIR");
        const std::string cand = dir ? std::string(dir) + "/armadillo-7k" : shared;
        if (FILE* f = std::fopen((cand + ".node").c_str(), "r")) {
            std::fclose(f);
            path = cand;
        }
    }
    Mesh mesh;
    if (path.empty()) {
        mesh = make_box_of_size(7554);
        origin = "generated box (armadillo-7k not found)";
        up = 2;
    } else if (is_box_spec(path)) {
        mesh = make_box_from_spec(path);
        origin = path;
        up = 2;
    } else {
        mesh = read_mesh(path);
        origin = path;
        up = 1;
    }
    validate_mesh(mesh);
    // Renumbered for memory locality (reverse Cuthill-McKee; the owner
    // variant's parts rely on it). The loop reports statistics only, so the
    // internal numbering never shows.
    if (o.ordering == "rcm") {
#ifdef EDGEFEM_HAPTIC_HAVE_PARTITION
        mesh = permute_mesh(mesh, vertex_ordering(mesh, Ordering::RCM));
#endif
    } else if (o.ordering != "input") {
        usage("--ordering: input or rcm");
    }
    return mesh;
}

// Vertices on the boundary (of faces that belong to one tet only).
std::vector<index_t> surface_vertices(const Mesh& mesh) {
    std::map<std::array<index_t, 3>, int> faces;
    static const int F[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (index_t t = 0; t < mesh.num_tets(); ++t)
        for (const auto& f : F) {
            std::array<index_t, 3> k{mesh.tets[4 * t + f[0]], mesh.tets[4 * t + f[1]], mesh.tets[4 * t + f[2]]};
            std::sort(k.begin(), k.end());
            ++faces[k];
        }
    std::vector<char> on(mesh.num_vertices(), 0);
    for (const auto& [k, n] : faces)
        if (n == 1)
            for (index_t v : k) on[v] = 1;
    std::vector<index_t> out;
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        if (on[v]) out.push_back(v);
    return out;
}

double percentile(const std::vector<double>& sorted, double p) {
    if (sorted.empty()) return 0;
    const double pos = p / 100.0 * double(sorted.size() - 1);
    const std::size_t i = std::size_t(pos);
    const double w = pos - double(i);
    return i + 1 < sorted.size() ? sorted[i] * (1 - w) + sorted[i + 1] * w : sorted[i];
}

template <class S>
int run(const Options& o) {
    std::string origin;
    int up = 1;
    Scene scene;
    scene.mesh = load(o, origin, up);
    const index_t nv = scene.mesh.num_vertices();
    const Mesh& mesh0 = scene.mesh;  // until the simulator takes the scene

    // Geometry: bounding box, base to glue, the probe's circle.
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (index_t v = 0; v < nv; ++v)
        for (int r = 0; r < 3; ++r) {
            lo[r] = std::min(lo[r], mesh0.X[3 * v + r]);
            hi[r] = std::max(hi[r], mesh0.X[3 * v + r]);
        }
    const double height = hi[up] - lo[up];
    for (index_t v = 0; v < nv; ++v)
        if (mesh0.X[3 * v + up] <= lo[up] + 0.05 * height) scene.fixed.push_back(v);
    const std::vector<index_t> surface = surface_vertices(mesh0);
    const int a1 = 0, a2 = up == 1 ? 2 : 1;  // the horizontal plane
    const double c1 = 0.5 * (lo[a1] + hi[a1]), c2 = 0.5 * (lo[a2] + hi[a2]);
    const double radius = 0.75 * std::max(hi[a1] - lo[a1], hi[a2] - lo[a2]);
    const double probe_h = lo[up] + 0.7 * height;
    const double omega = 2 * M_PI / 2.0;  // one turn every 2 s

    scene.materials = Material{o.young, o.poisson, o.density};
    scene.model = o.model == "sn" ? ModelKind::SN : ModelKind::FE;
    double g[3] = {0, 0, 0};
    g[up] = -o.gravity;
    scene.gravity = {g[0], g[1], g[2]};
    scene.integrator = Integrator::SemiImplicit;
    scene.dt = 1.0 / o.rate;
    scene.rayleigh_alpha = o.alpha;  // light damping so the poked body settles
    scene.solver.definite_stiffness = o.definite;
    scene.solver.cg_fixed_iterations = o.cg_iters;
    scene.solver.stiffness_interval = o.stiffness_interval;
    scene.count_inverted_tets = false;  // a statistic the loop does not need

    std::shared_ptr<const Executor> executor;
    OperatorFactory<S> factory;  // empty: the reference back-end
    std::string backend = "serial";
    int threads = 1;
#ifdef EDGEFEM_HAPTIC_HAVE_PARALLEL
    factory = cpu_operator_factory<S>();  // the CPU back-end's serial loops
    if (o.backend != "serial") {
        executor = make_executor(parse_backend(o.backend), o.threads);
        factory = cpu_operator_factory<S>({executor, parse_variant(o.variant)});
        backend = executor->name();
        threads = executor->threads();
    }
    // The tangent on a background thread (the second core), K swapped in
    // when ready; the loop's thread only computes forces and runs CG.
    if (o.async_tangent) factory = async_tangent_factory<S>(factory);
#else
    if (o.backend != "serial") usage("this build has no parallel module: --backend serial only");
    if (o.async_tangent) usage("this build has no parallel module: no --async-tangent");
#endif
    Simulator<S> sim(std::move(scene), executor, factory);
    const Mesh& mesh = sim.scene().mesh;

    std::printf("mesh: %s\nvertices: %d\ntets: %d\nfixed_vertices: %zu\nsurface_vertices: %zu\n", origin.c_str(),
                nv, sim.scene().mesh.num_tets(), sim.scene().fixed.size(), surface.size());
    std::printf("integrator: semi-implicit\nmodel: %s\nprecision: %s\nbackend: %s\nthreads: %d\nvariant: %s\nordering: %s\n",
                o.model.c_str(), o.precision.c_str(), backend.c_str(), threads,
                o.backend == "serial" ? "-" : o.variant.c_str(), o.ordering.c_str());
    std::printf("young_pa: %g\nrayleigh_alpha: %g\ndefinite_stiffness: %s\n", o.young, o.alpha,
                o.definite ? "true" : "false");
    std::printf("stiffness_interval: %d\nasync_tangent: %s\n", o.stiffness_interval, o.async_tangent ? "true" : "false");
    std::printf("spin_us: %d\n", o.spin_us);
    std::printf("cg_fixed_iterations: %d\nrate_hz: %g\nbudget_ms: %g\nprobe_force_n: %g\n", o.cg_iters, o.rate,
                1e3 / o.rate, o.force);

    const auto period = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(1.0 / o.rate));
    const long ticks = long(std::llround(o.seconds * o.rate));
    std::vector<double> step_ms;
    step_ms.reserve(ticks);
    long missed = 0, steps = 0;
    double parts[3] = {0, 0, 0};  // summed force / stiffness / solve ms
    std::vector<std::pair<double, index_t>> near(surface.size());
    std::vector<index_t> probed;

    const auto start = clock_type::now();
    for (long tick = 0; tick < ticks;) {
        const auto deadline = start + (tick + 1) * period;
        // The probe: its position at this tick's time, pushing inwards on the
        // nearest surface vertices.
        const double t = double(tick) / o.rate;
        const double p1 = c1 + radius * std::cos(omega * t), p2 = c2 + radius * std::sin(omega * t);
        auto fe = sim.external_forces();
        for (index_t v : probed) fe[3 * v] = fe[3 * v + 1] = fe[3 * v + 2] = S(0);
        for (std::size_t i = 0; i < surface.size(); ++i) {
            const index_t v = surface[i];
            const double d1 = mesh.X[3 * v + a1] - p1, d2 = mesh.X[3 * v + a2] - p2, dh = mesh.X[3 * v + up] - probe_h;
            near[i] = {d1 * d1 + d2 * d2 + dh * dh, v};
        }
        const int k = std::min<int>(o.probe_vertices, int(near.size()));
        std::partial_sort(near.begin(), near.begin() + k, near.end());
        probed.clear();
        const double d1 = c1 - p1, d2 = c2 - p2, dn = std::hypot(d1, d2);
        for (int j = 0; j < k; ++j) {
            const index_t v = near[j].second;
            probed.push_back(v);
            fe[3 * v + a1] = S(o.force / k * d1 / dn);
            fe[3 * v + a2] = S(o.force / k * d2 / dn);
        }

        const auto t0 = clock_type::now();
        try {
            sim.step();
        } catch (const SimulationError& e) {
            std::printf("simulation failed at tick %ld: %s\n", tick, e.what());
            return 3;
        }
        const auto t1 = clock_type::now();
        const StepStats& st = sim.last_stats();
        parts[0] += st.force_ms;
        parts[1] += st.stiffness_ms;
        parts[2] += st.solve_ms;
        ++steps;
        step_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        if (o.free_run) {
            ++tick;
        } else if (t1 > deadline) {
            ++missed;
            // Skip the ticks whose slot has already passed; they are
            // reported as dropped (ticks - steps).
            tick = std::min(ticks, std::max(tick + 1, long((t1 - start) / period)));
        } else {
            // Sleep to shortly before the tick, then spin: a sleeping
            // thread's wake-up can be late by a few hundred µs on a loaded
            // non-real-time kernel, which alone missed about half the
            // deadlines that were missed (the loop's core is its own).
            const auto wake = deadline - std::chrono::microseconds(o.spin_us);
            if (clock_type::now() < wake) std::this_thread::sleep_until(wake);
            while (clock_type::now() < deadline) {
            }
            ++tick;
        }
    }
    const double wall = std::chrono::duration<double>(clock_type::now() - start).count();

    std::vector<double> sorted = step_ms;
    std::sort(sorted.begin(), sorted.end());
    double mean = 0;
    for (double x : step_ms) mean += x;
    mean /= double(step_ms.size());
    const double budget = 1e3 / o.rate;
    long over = 0;
    for (double x : step_ms) over += x > budget;
    const auto us = sim.displacement();
    double umax = 0;
    bool finite = true;
    for (std::size_t i = 0; i < us.size(); ++i) {
        finite = finite && std::isfinite(double(us[i]));
        umax = std::max(umax, std::abs(double(us[i])));
    }
    std::printf("ticks: %ld\nsteps: %ld\nwall_s: %.3f\nsimulated_s: %.3f\nrealtime_factor: %.3f\n", ticks, steps, wall,
                double(steps) / o.rate, double(steps) / o.rate / wall);
    std::printf("missed_deadlines: %ld (%.1f%% of steps)\ndropped_ticks: %ld\n", missed,
                100.0 * double(missed) / double(steps), ticks - steps);
    std::printf("steps_over_budget: %ld (%.1f%%)\n", over, 100.0 * double(over) / double(steps));
    std::printf("step_ms: mean %.3f min %.3f p50 %.3f p90 %.3f p99 %.3f p99.9 %.3f max %.3f\n", mean, sorted.front(),
                percentile(sorted, 50), percentile(sorted, 90), percentile(sorted, 99), percentile(sorted, 99.9),
                sorted.back());
    std::printf("mean_ms: force %.3f stiffness %.3f solve %.3f\n", parts[0] / double(steps), parts[1] / double(steps),
                parts[2] / double(steps));
    std::printf("max_displacement_mm: %.3f\nfinite: %s\n", 1e3 * umax, finite ? "true" : "false");
    // Keeping up: every tick got its step (none dropped for lack of time);
    // meeting every deadline is the stricter statement.
    std::printf("keeps_up: %s\nevery_deadline_met: %s\n", ticks == steps ? "yes" : "no", missed == 0 ? "yes" : "no");
    return finite ? 0 : 3;
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);
    try {
        return o.precision == "float" ? run<float>(o) : run<double>(o);
    } catch (const Error& e) {
        std::fprintf(stderr, "edgefem_haptic_loop: %s\n", e.what());
        return 2;
    }
}
