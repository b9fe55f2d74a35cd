// `edgefem static SCENE.json --out PREFIX`: static equilibrium of a scene
// under its gravity and prescribed targets.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "common.hpp"
#include "edgefem/core/simulator.hpp"
#include "frame_writer.hpp"
#include "edgefem/partition/ordered_simulator.hpp"
#include "output_paths.hpp"
#include "sim_common.hpp"

namespace edgefem::cli {

namespace {

struct StaticOptions {
    std::string scene, out;
    std::string format;  // non-empty overrides output.format (binary or ascii)
    bool quiet = false;  // no progress on stderr
    RunOptions run;  // its ordering: the internal numbering
};

// Newton's progress on stderr: one line redrawn in place on a terminal,
// else a line per iteration.
class StaticProgressLine {
public:
    StaticProgressLine() : tty_(::isatty(::fileno(stderr)) == 1) {}
    ~StaticProgressLine() { finish(); }

    void update(const StaticProgress& p) {
        std::fprintf(stderr, "%sedgefem: load step %d (load %.4g%%): Newton iterations %d, relative residual %.3e%s",
                     tty_ ? "\r" : "", p.load_step, 100 * p.load_fraction, p.newton_iterations, p.residual,
                     tty_ ? "  " : "\n");
        open_ = tty_;
    }
    // Ends the line (before the summary or an error message).
    void finish() {
        if (open_) std::fputc('\n', stderr);
        open_ = false;
    }

private:
    bool tty_;
    bool open_ = false;
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
    // The volume as VTU: the scene's output.fields, output.format when it is
    // binary or ascii (a surface's PLY or OBJ is simulate's).
    OutputSettings output = sf.output;
    output.mesh = OutputMesh::Volume;
    if (!opts.format.empty()) output.format = parse_output_format(opts.format, OutputMesh::Volume, "--format");
    if (output.format != OutputFormat::Ascii) output.format = OutputFormat::Binary;
    if (!sf.file_vertex.empty()) check_replaceable(opts.out + ".vertex-map", kVertexMapSignature);
    const auto executor = make_run_executor(opts.run);
    OrderedSimulator<double> osim(sf.scene, parse_ordering(opts.run.ordering),
                                  make_run_backend<double>(opts.run, executor));
    const Simulator<double>& sim = osim.internal();
    StaticProgressLine line;
    StaticResult r;
    if (opts.quiet) {
        r = osim.solve_static();
    } else {
        r = osim.solve_static([&](const StaticProgress& p) { line.update(p); });
        line.finish();
    }

    std::vector<double> u(3 * std::size_t(sf.scene.mesh.num_vertices())), f(u.size());
    osim.get_displacement(u);
    osim.get_forces(f);
    write_vectors(opts.out + ".disp", u);
    FrameWriter(sf.scene, output, sf.file_vertex).write(opts.out + ".vtu", u, {}, f);
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
        "with line search and automatic load stepping, showing its progress on stderr; writes PREFIX.disp (one 'ux uy uz' line per vertex, "
        "%.17g) and PREFIX.vtu");
    // An empty SCENE would mean the built-in beam (load_scene_file).
    cmd->add_option("SCENE", opts->scene, "Scene file (JSON, see docs/scenes.md)")->required()->check(non_empty_path());
    cmd->add_option("--out", opts->out, "Output file prefix")->required()->check(non_empty_path());
    cmd->add_option("--format", opts->format,
                    "PREFIX.vtu as binary (compressed, the default) or ascii; overrides the scene's output.format");
    cmd->add_flag("--quiet", opts->quiet, "No progress (load steps, Newton iterations, residuals) on stderr");
    cmd->footer(kExitCodesHelp);
    add_ordering_option(*cmd, opts->run.ordering);
    add_run_options(*cmd, opts->run);
    cmd->callback([opts] { run_static(*opts); });
}

}  // namespace edgefem::cli
