// `edgefem static SCENE.json --out PREFIX`: static equilibrium of a scene
// under its gravity and prescribed targets.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "common.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "edgefem/partition/ordered_simulator.hpp"
#include "output_paths.hpp"
#include "sim_common.hpp"

namespace edgefem::cli {

namespace {

struct StaticOptions {
    std::string scene, out;
    RunOptions run;  // its ordering: the internal numbering
};

void run_static(const StaticOptions& opts) {
    const auto t0 = std::chrono::steady_clock::now();
    // The files are written after the solve (minutes on a large mesh): a
    // typo in the folder should not cost the solve.
    check_writable("--out", opts.out + ".disp");
    check_writable("--out", opts.out + ".vtu");
    check_replaceable(opts.out + ".disp", "");
    check_replaceable(opts.out + ".vtu", kVtuSignature);
    SceneFile sf = load_scene_file(opts.scene);
    if (!sf.file_vertex.empty()) check_replaceable(opts.out + ".vertex-map", kVertexMapSignature);
    const auto executor = make_run_executor(opts.run);
    OrderedSimulator<double> osim(sf.scene, parse_ordering(opts.run.ordering),
                                  make_run_backend<double>(opts.run, executor));
    const Simulator<double>& sim = osim.internal();
    const StaticResult r = osim.solve_static();

    std::vector<double> u(3 * std::size_t(sf.scene.mesh.num_vertices())), f(u.size());
    osim.get_displacement(u);
    osim.get_forces(f);
    write_vectors(opts.out + ".disp", u);
    FrameWriter(sf.scene, sf.file_vertex).write(opts.out + ".vtu", u, f);
    // Compaction renumbered the vertices: the .disp lines and .vtu points
    // follow the scene's numbering; the map leads back to the file's.
    if (!sf.file_vertex.empty()) write_vertex_map(opts.out + ".vertex-map", sf.file_vertex);

    print_kv("vertices", sim.num_vertices());
    print_kv("tets", sim.scene().mesh.num_tets());
    print_kv("ordering", opts.run.ordering);
    print_kv("backend", describe(opts.run, executor.get()));
    print_kv("newton_iterations", r.newton_iterations);
    print_kv("load_steps", r.load_steps);
    print_kv("residual", fmt(r.residual, 6));
    print_kv("converged", r.converged ? "true" : "false");
    print_kv("inverted_tets", sim.last_stats().inverted_tets);
    if (executor) print_adaptive(*executor);
    print_kv("wall_s", fmt(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 6));
    // The files are written either way: the last state helps to see why.
    if (!r.converged)
        throw SimulationError("static solve did not converge (residual " + fmt(r.residual, 3) + ")", sim.step_index());
    if (const index_t inverted = sim.last_stats().inverted_tets; inverted > 0) {
        if (sf.scene.solver.fail_on_inverted)
            throw SimulationError("the equilibrium has " + std::to_string(inverted) +
                                      " inverted tets (negative volume) and solver.fail_on_inverted is set",
                                  sim.step_index());
        std::fprintf(stderr, "edgefem: warning: the equilibrium has %ld of %ld tets inverted (negative volume): "
                     "the result is suspect (solver.fail_on_inverted makes this an error)\n",
                     long(inverted), long(sf.scene.mesh.num_tets()));
    }
}

}  // namespace

void add_static_command(CLI::App& app) {
    auto opts = std::make_shared<StaticOptions>();
    auto* cmd = app.add_subcommand(
        "static",
        "Static equilibrium of a scene (docs/scenes.md) under gravity and its prescribed targets, by Newton "
        "with line search and automatic load stepping; writes PREFIX.disp (one 'ux uy uz' line per vertex, "
        "%.17g) and PREFIX.vtu");
    // An empty SCENE would mean the built-in beam (load_scene_file).
    cmd->add_option("SCENE", opts->scene, "Scene file (JSON, see docs/scenes.md)")->required()->check(non_empty_path());
    cmd->add_option("--out", opts->out, "Output file prefix")->required()->check(non_empty_path());
    cmd->footer(kExitCodesHelp);
    add_ordering_option(*cmd, opts->run.ordering);
    add_run_options(*cmd, opts->run);
    cmd->callback([opts] { run_static(*opts); });
}

}  // namespace edgefem::cli
