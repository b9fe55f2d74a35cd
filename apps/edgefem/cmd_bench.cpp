// `edgefem bench MESH --kernel K`: times one kernel on the twist
// configuration, or one semi-implicit time step, one steady_clock reading per
// call. For the edge method's force and kx kernels it also reports the bytes
// a call moves from memory (compulsory traffic, stream_bandwidth.hpp) and the
// rate that makes; --stream measures the STREAM bandwidth on the same
// executor in the same run and prints the kernel's fraction of it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>

#include "common.hpp"
#include "edgefem/parallel/adaptive_executor.hpp"
#include "timing.hpp"
#include "lab/benchmark_scene.hpp"
#include "edgefem/core/coefficients.hpp"
#include "lab/deformations.hpp"
#include "cpu/tet_edge_form.hpp"
#include "edgefem/core/topology.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/cpu_operator.hpp"
#include "lab/barrier_latency.hpp"
#include "lab/stream_bandwidth.hpp"

namespace edgefem::cli {

namespace {

struct BenchOptions {
    MeshOptions mesh;
    ModelOptions model;
    RunOptions run;
    std::string kernel;
    double seconds = 1.0;
    int cg_iters = 0;  // step: > 0 runs exactly this many CG iterations
    double dt = 1e-3;  // step: the time step (s)
    std::string preconditioner = "auto";  // step: CG's preconditioner
    std::string linear = "cg";  // step: cg or direct
    bool stream = false;  // also measure the STREAM bandwidth on the same executor
    int stream_rounds = 5;  // with stream: kernel and triad alternate this many times
};

const std::map<std::string, Kernel> kKernels = {{"force", Kernel::Force},
                                                {"stiffness", Kernel::Stiffness},
                                                {"force+stiffness", Kernel::ForceStiffness},
                                                {"kx", Kernel::Kx}};

void print_header(const BenchOptions& opts, const Mesh& mesh) {
    print_kv("mesh", opts.mesh.path);
    print_kv("ordering", opts.mesh.ordering);
    print_kv("vertices", mesh.num_vertices());
    print_kv("tets", mesh.num_tets());
    print_kv("kernel", opts.kernel);
    print_kv("method", opts.model.method);
    print_kv("model", opts.model.model);
    print_kv("precision", opts.model.precision);
    print_kv("layout", opts.model.layout);
    print_kv("backend", describe(opts.run, make_run_executor(opts.run).get()));
}

// The executor's threads themselves: the barrier probe and the triad time
// them, never an adaptive choice of the calling thread.
const Executor& threads_of(const Executor& ex) {
    if (const auto* a = dynamic_cast<const AdaptiveExecutor*>(&ex)) return a->inner();
    return ex;
}

// The executor the STREAM triad runs on: the run's, one thread for the
// serial loops.
std::shared_ptr<const Executor> stream_executor(const RunOptions& run) {
    auto ex = make_run_executor(run);
    return ex ? ex : std::make_shared<SerialExecutor>();
}

// On more than one thread, what a phase boundary costs right before and
// after the timed calls (barrier_latency.hpp says why).
struct BarrierProbe {
    std::shared_ptr<const Executor> ex;
    bool on;
    double before = 0, after = 0;
    explicit BarrierProbe(std::shared_ptr<const Executor> e) : ex(std::move(e)), on(ex && ex->threads() > 1) {
        if (on) before = phase_barrier_us(threads_of(*ex));
    }
    void finish() {
        if (on) after = phase_barrier_us(threads_of(*ex));
    }
    void print() const {
        if (!on) return;
        print_kv("phase_barrier_us_before", fmt(before, 4));
        print_kv("phase_barrier_us_after", fmt(after, 4));
    }
};

// One semi-implicit step (dt = 1 ms) of the mesh standing on its lowest 1%
// along z under gravity -z; the state moves on from call to call.
template <class S>
void bench_step(const BenchOptions& opts, Mesh mesh) {
    Scene scene = step_benchmark_scene(std::move(mesh), opts.model.material);
    scene.model = opts.model.kind();
    scene.method = opts.model.method_kind() == Method::Tet ? edgefem::Method::Tet : edgefem::Method::Edge;
    scene.solver.cg_tolerance = 1e-6;
    scene.solver.cg_fixed_iterations = opts.cg_iters;
    scene.dt = opts.dt;
    scene.solver.preconditioner = parse_preconditioner(opts.preconditioner, "--preconditioner");
    scene.solver.linear_solver = opts.linear == "direct" ? LinearSolver::Direct : LinearSolver::CG;
    scene.validate();
    const auto ex = make_run_executor(opts.run);
    Simulator<S> sim(std::move(scene), ex, operator_factory<S>(opts.run, ex, opts.model.layout_kind()));

    // The first step alone: it holds the one-off set-up (the AMG's
    // hierarchy, the direct solver's analysis).
    const auto t0 = std::chrono::steady_clock::now();
    sim.step();
    const double first_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::vector<int> iterations;  // of the timed calls (cleared after the warm-up, so bounded as they are)
    std::vector<double> setup_ms;  // K and the solver's set-up per step (StepStats::stiffness_ms)
    BarrierProbe probe(ex);
    const std::vector<double> ns = time_calls(
        opts.seconds,
        [&] {
            const StepStats& st = sim.step();
            iterations.push_back(st.solver_iterations);
            setup_ms.push_back(st.stiffness_ms);
        },
        5, kMaxTimedCalls,
        [&] {
            iterations.clear();
            setup_ms.clear();
        });
    probe.finish();
    std::sort(setup_ms.begin(), setup_ms.end());
    double mean_iterations = 0;
    for (int i : iterations) mean_iterations += i;
    mean_iterations /= double(iterations.size());
    const double median = median_of_sorted(ns), tets = sim.scene().mesh.num_tets();

    print_header(opts, sim.scene().mesh);
    print_kv("fixed_vertices", sim.scene().fixed.size());
    print_kv("dt", fmt(sim.scene().dt, 6));
    print_kv("linear", opts.linear);
    if (opts.linear == "cg") print_kv("preconditioner", opts.preconditioner);
    print_kv("first_step_ms", fmt(first_ms, 6));
    print_kv("median_setup_ms_per_step", fmt(median_of_sorted(setup_ms), 6));
    print_kv("steps", ns.size());
    print_kv("median_ms_per_step", fmt(median * 1e-6, 6));
    print_kv("min_ms_per_step", fmt(ns.front() * 1e-6, 6));
    print_kv("median_ns_per_tet", fmt(median / tets, 6));
    print_kv("cg_iterations", fmt(mean_iterations, 6));
    print_kv("cg_iterations_max", *std::max_element(iterations.begin(), iterations.end()));
    probe.print();
    if (ex) print_adaptive(*ex);
}

// Bytes one call of `kernel` moves (compulsory and per-pass counts,
// stream_bandwidth.hpp), from an edge model (and form) built for the purpose
// and freed before the timed calls; {0, 0} where no model applies (per-tet
// method, stiffness, force+stiffness).
struct Traffic {
    double compulsory = 0, per_pass = 0;
};

// `form_forces`: the force call takes g from the tet-local form
// (Evaluator::forces_from_tet_local_form); `state_stored`: it writes its
// edge state to mesh-wide arrays (Evaluator::forces_stored_state).
template <class S>
Traffic kernel_traffic_as(const BenchOptions& opts, const Mesh& mesh, Kernel kernel, bool form_forces,
                          bool state_stored) {
    const Topology topo = build_topology(mesh);
    const EdgeModel<S> m = make_edge_model<S>(topo, compute_coefficients(mesh, topo, opts.model.material));
    if (kernel == Kernel::Force && form_forces) {
        const TetEdgeForm<S> form = make_tet_edge_form<S>(mesh, topo, opts.model.material);
        return {form_force_bytes_per_call(m, form, TrafficModel::Compulsory, state_stored),
                form_force_bytes_per_call(m, form, TrafficModel::PerPass, state_stored)};
    }
    if (kernel == Kernel::Force)
        return {force_bytes_per_call(m, opts.model.kind(), TrafficModel::Compulsory),
                force_bytes_per_call(m, opts.model.kind(), TrafficModel::PerPass)};
    return {kx_bytes_per_call(m, TrafficModel::Compulsory), kx_bytes_per_call(m, TrafficModel::PerPass)};
}

Traffic kernel_traffic(const BenchOptions& opts, const Mesh& mesh, Kernel kernel, bool form_forces, bool state_stored) {
    if (opts.model.method_kind() != Method::Edge || (kernel != Kernel::Force && kernel != Kernel::Kx)) return {};
    return opts.model.precision_kind() == Precision::Float
               ? kernel_traffic_as<float>(opts, mesh, kernel, form_forces, state_stored)
               : kernel_traffic_as<double>(opts, mesh, kernel, form_forces, state_stored);
}

void run_bench(const BenchOptions& opts) {
    opts.model.validate();
    if (opts.stream && opts.kernel == "step") throw InvalidArgument("--stream does not apply to --kernel step");
    if (opts.cg_iters > 0 && opts.kernel != "step") throw InvalidArgument("--cg-iters applies only to --kernel step");
    if (opts.kernel != "step" && (opts.dt != 1e-3 || opts.preconditioner != "auto" || opts.linear != "cg"))
        throw InvalidArgument("--dt, --preconditioner and --linear apply only to --kernel step");
    parse_preconditioner(opts.preconditioner, "--preconditioner");  // a bad name fails before the mesh loads
    LoadedMesh lm = load_mesh(opts.mesh);
    check_mesh_scale(lm.mesh, opts.model.precision_kind(), opts.mesh.path);
    // The step's scene gives every vertex mass from its tets; without this
    // check the scene's own "vertex 5 has no mass" names a scene the user
    // never wrote. Before the warnings, so that the error is the one line.
    if (const index_t n = lm.validation.unreferenced_vertices - lm.validation.removed_vertices;
        opts.kernel == "step" && n > 0)
        throw InvalidArgument(opts.mesh.path + ": the mesh has unreferenced vertices (" + std::to_string(n) +
                              " that no tet uses, so they would have no mass in --kernel step): pass "
                              "--compact to remove them");
    for (const auto& w : load_warnings(lm)) std::fprintf(stderr, "edgefem: warning: %s\n", w.c_str());
    if (opts.kernel == "step") {
        if (opts.model.precision_kind() == Precision::Float)
            bench_step<float>(opts, std::move(lm.mesh));
        else
            bench_step<double>(opts, std::move(lm.mesh));
        return;
    }
    const Kernel kernel = kKernels.at(opts.kernel);
    const Mesh& mesh = lm.mesh;
    auto eval = make_evaluator(mesh, opts.model, opts.run);
    eval->set_displacement(deformation_displacement(mesh, Deformation::Twist));
    // kx multiplies a generic (non-smooth) vector.
    eval->prepare(kernel, deformation_displacement(mesh, Deformation::Random));
    eval->run(kernel);  // one call, so that the operator says where its force state went
    const Traffic traffic =
        kernel_traffic(opts, mesh, kernel, eval->forces_from_tet_local_form(), eval->forces_stored_state());

    const auto call = [&] {
        eval->run(kernel);
        eval->consume();
    };
    // With --stream, the timed calls and STREAM alternate in rounds on the
    // kernels' executor (same back-end and threads, the kernel's data still
    // allocated): on a shared machine the bandwidth on offer drifts within
    // seconds, so each round's calls are set against the triad measured
    // right after them, and the median of those paired fractions is
    // reported next to the fraction of the overall medians.
    BarrierProbe probe(make_run_executor(opts.run));
    const int rounds = opts.stream ? opts.stream_rounds : 1;
    std::vector<double> ns, round_fraction;
    std::vector<StreamBandwidth> sb;
    for (int r = 0; r < rounds; ++r) {
        // The cap on stored durations holds for all rounds together.
        std::vector<double> t = time_calls(opts.seconds / rounds, call, 5, kMaxTimedCalls / std::size_t(rounds));
        if (opts.stream) {
            StreamOptions so;
            so.repetitions = 3;
            sb.push_back(measure_stream_bandwidth(threads_of(*stream_executor(opts.run)), so));
            round_fraction.push_back(traffic.compulsory / median_of_sorted(t) / sb.back().triad);
        }
        ns.insert(ns.end(), t.begin(), t.end());
    }
    probe.finish();
    std::sort(ns.begin(), ns.end());
    const double median = median_of_sorted(ns);
    const double tets = mesh.num_tets();
    // The median over the rounds of one STREAM rate.
    const auto stream_median = [&](double StreamBandwidth::*rate) {
        std::vector<double> v;
        for (const auto& b : sb) v.push_back(b.*rate);
        std::sort(v.begin(), v.end());
        return median_of_sorted(v);
    };

    print_header(opts, mesh);
    print_kv("calls", ns.size());
    print_kv("median_ms", fmt(median * 1e-6, 6));
    print_kv("min_ms", fmt(ns.front() * 1e-6, 6));
    print_kv("median_ns_per_tet", fmt(median / tets, 6));
    print_kv("min_ns_per_tet", fmt(ns.front() / tets, 6));
    probe.print();
    const double achieved = traffic.compulsory / median;  // bytes per ns = GB/s
    if (traffic.compulsory > 0) {
        print_kv("bytes_per_call", fmt(traffic.compulsory, 10));
        print_kv("achieved_GB_per_s", fmt(achieved, 6));
        print_kv("bytes_per_call_per_pass", fmt(traffic.per_pass, 10));
        print_kv("achieved_GB_per_s_per_pass", fmt(traffic.per_pass / median, 6));
    }
    if (opts.stream) {
        const double triad = stream_median(&StreamBandwidth::triad);
        double triad_best = 0;
        for (const auto& b : sb) triad_best = std::max(triad_best, b.triad_best);
        print_kv("stream_threads", sb.front().threads);
        print_kv("stream_rounds", rounds);
        print_kv("stream_copy_GB_per_s", fmt(stream_median(&StreamBandwidth::copy), 6));
        print_kv("stream_scale_GB_per_s", fmt(stream_median(&StreamBandwidth::scale), 6));
        print_kv("stream_add_GB_per_s", fmt(stream_median(&StreamBandwidth::add), 6));
        print_kv("stream_triad_GB_per_s", fmt(triad, 6));
        print_kv("stream_sum_GB_per_s", fmt(stream_median(&StreamBandwidth::sum), 6));
        print_kv("stream_triad_best_GB_per_s", fmt(triad_best, 6));
        if (traffic.compulsory > 0) {
            print_kv("fraction_of_stream", fmt(achieved / triad, 4));
            // Each round's median call against the triad right after it.
            std::string each;
            for (double f : round_fraction) each += (each.empty() ? "" : " ") + fmt(f, 4);
            print_kv("fraction_of_stream_rounds", each);
            std::sort(round_fraction.begin(), round_fraction.end());
            print_kv("fraction_of_stream_paired", fmt(median_of_sorted(round_fraction), 4));
            // Fastest call against fastest triad: the least disturbed pair on
            // a shared machine (STREAM itself reports best times).
            print_kv("fraction_of_stream_best", fmt(traffic.compulsory / ns.front() / triad_best, 4));
        }
    }
}

}  // namespace

void add_bench_command(CLI::App& app) {
    auto opts = std::make_shared<BenchOptions>();
    auto* cmd = app.add_subcommand(
        "bench",
        "Time one kernel on the twist configuration, or one time step, on the chosen back-end (--backend, --threads, --variant): a warm-up, then "
        "calls until --seconds have passed (at least 5, at most 2^22 = 4194304 timed calls: timing stops there on tiny meshes); reports the median and minimum per call and per tet, and for the edge method's force and kx the "
        "bytes a call moves from memory (bytes_per_call) and the rate achieved (achieved_GB_per_s); on more than one thread, what an "
        "empty phase boundary costs before and after the timed calls (phase_barrier_us_before/after: where the threads sit)");
    add_mesh_options(*cmd, opts->mesh);
    add_model_options(*cmd, opts->model, /*material_required=*/false);
    // A benchmark times the back-end it is given: no adaptive choice unless asked.
    opts->run.adaptive = false;
    add_run_options(*cmd, opts->run);
    cmd->add_option("--kernel", opts->kernel,
                    "force: forces only (no energy); stiffness: K from a previous force call's state (edge) or "
                    "the per-tet 12x12 blocks (tet); force+stiffness: both; kx: y = K x with K precomputed "
                    "(edge: per-edge blocks, tet: stored per-tet blocks); step: one semi-implicit step "
                    "(--dt, 1 ms by default; gravity -z, the lowest 1% of the mesh along z fixed, CG to 1e-6 or "
                    "--cg-iters iterations, --preconditioner, or --linear direct), successive steps from the moving "
                    "state; it reports the first step (the one-off set-up) apart")
        ->required()
        ->check(CLI::IsMember({"force", "stiffness", "force+stiffness", "kx", "step"}));
    auto* stream_flag = cmd->add_flag("--stream", opts->stream,
                  "Also measure the STREAM bandwidth (copy, scale, add, triad, read-only sum; 3 x 64 MiB) on the same "
                  "back-end and threads, alternating with the timed calls (--stream-rounds), and print the kernel's "
                  "fraction of the triad rate (edge force and kx: bytes_per_call / median time)");
    cmd->add_option("--stream-rounds", opts->stream_rounds,
                    "With --stream: alternate the timed calls (--seconds split evenly) and STREAM (median of 3) this "
                    "many times; fraction_of_stream_paired is the median over the rounds of each round's median call "
                    "against the triad measured right after it")
        ->check(int_in_range(1, 1000))
        ->needs(stream_flag)
        ->capture_default_str();
    cmd->add_option("--cg-iters", opts->cg_iters,
                    "step: run exactly N warm-started CG iterations per step instead of solving to 1e-6")
        ->check(int_in_range(1));
    cmd->add_option("--dt", opts->dt, "step: the time step (s), at most 1")->check(seconds_at_most(1))->capture_default_str();
    cmd->add_option("--preconditioner", opts->preconditioner,
                    "step: CG's preconditioner: auto, block-jacobi or amg (docs/solvers.md)")
        ->capture_default_str();
    cmd->add_option("--linear", opts->linear, "step: cg (matrix-free, --preconditioner) or direct (CHOLMOD)")
        ->check(CLI::IsMember({"cg", "direct"}))
        ->capture_default_str();
    cmd->add_option("--seconds", opts->seconds, "Time budget of the timed calls, at most 3600")
        ->check(seconds_at_most(3600))
        ->capture_default_str();
    cmd->callback([opts] { run_bench(*opts); });
}

}  // namespace edgefem::cli
