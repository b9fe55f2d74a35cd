// `edgefem bench MESH --kernel K`: times one kernel on the twist
// configuration, one steady_clock reading per call.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>

#include "common.hpp"
#include "edgefem/core/deformations.hpp"

namespace edgefem::cli {

namespace {

struct BenchOptions {
    MeshOptions mesh;
    ModelOptions model;
    std::string kernel;
    double seconds = 1.0;
};

const std::map<std::string, Kernel> kKernels = {{"force", Kernel::Force},
                                                {"stiffness", Kernel::Stiffness},
                                                {"force+stiffness", Kernel::ForceStiffness},
                                                {"kx", Kernel::Kx}};

void run_bench(const BenchOptions& opts) {
    opts.model.validate();
    const Kernel kernel = kKernels.at(opts.kernel);
    const LoadedMesh lm = load_mesh(opts.mesh);
    const Mesh& mesh = lm.mesh;
    for (const auto& w : load_warnings(lm)) std::fprintf(stderr, "edgefem: warning: %s\n", w.c_str());

    auto eval = make_evaluator(mesh, opts.model);
    eval->set_displacement(deformation_displacement(mesh, Deformation::Twist));
    // kx multiplies a generic (non-smooth) vector.
    eval->prepare(kernel, deformation_displacement(mesh, Deformation::Random));

    using clock = std::chrono::steady_clock;
    const auto budget = std::chrono::duration<double>(opts.seconds);
    // Warm-up (caches, page faults, clock ramp-up): 5% of the budget, at least one call.
    for (const auto w0 = clock::now(); ;) {
        eval->run(kernel);
        eval->consume();
        if (clock::now() - w0 >= 0.05 * budget) break;
    }
    std::vector<double> ns;
    for (const auto start = clock::now(); ns.size() < 5 || clock::now() - start < budget;) {
        const auto t0 = clock::now();
        eval->run(kernel);
        eval->consume();
        const auto t1 = clock::now();
        ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
    }
    std::sort(ns.begin(), ns.end());
    const std::size_t n = ns.size();
    const double median = n % 2 ? ns[n / 2] : 0.5 * (ns[n / 2 - 1] + ns[n / 2]);
    const double tets = mesh.num_tets();

    print_kv("mesh", opts.mesh.path);
    print_kv("vertices", mesh.num_vertices());
    print_kv("tets", mesh.num_tets());
    print_kv("kernel", opts.kernel);
    print_kv("method", opts.model.method);
    print_kv("model", opts.model.model);
    print_kv("precision", opts.model.precision);
    print_kv("calls", n);
    print_kv("median_ms", fmt(median * 1e-6, 6));
    print_kv("min_ms", fmt(ns.front() * 1e-6, 6));
    print_kv("median_ns_per_tet", fmt(median / tets, 6));
    print_kv("min_ns_per_tet", fmt(ns.front() / tets, 6));
}

}  // namespace

void add_bench_command(CLI::App& app) {
    auto opts = std::make_shared<BenchOptions>();
    auto* cmd = app.add_subcommand(
        "bench",
        "Time one kernel on the twist configuration (single thread): a warm-up, then calls until --seconds "
        "have passed (at least 5); reports the median and minimum per call and per tet");
    add_mesh_options(*cmd, opts->mesh);
    add_model_options(*cmd, opts->model, /*material_required=*/false);
    cmd->add_option("--kernel", opts->kernel,
                    "force: forces only (no energy); stiffness: K from a previous force call's state (edge) or "
                    "the per-tet 12x12 blocks (tet); force+stiffness: both; kx: y = K x with K precomputed "
                    "(edge: per-edge blocks, tet: stored per-tet blocks)")
        ->required()
        ->check(CLI::IsMember({"force", "stiffness", "force+stiffness", "kx"}));
    cmd->add_option("--seconds", opts->seconds, "Time budget of the timed calls")
        ->check(CLI::Validator(
            [](std::string& s) {
                double v = 0;
                return CLI::detail::lexical_cast(s, v) && v > 0 ? std::string() : "must be a positive number, got " + s;
            },
            "POSITIVE"))
        ->capture_default_str();
    cmd->callback([opts] { run_bench(*opts); });
}

}  // namespace edgefem::cli
