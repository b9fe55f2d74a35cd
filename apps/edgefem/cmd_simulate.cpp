// `edgefem simulate [SCENE.json]`: steps a scene (or the built-in beam),
// writes VTU frames and a .pvd series, and prints per-step timings.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "common.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "frame_writer.hpp"
#include "edgefem/partition/ordered_simulator.hpp"
#include "output_paths.hpp"
#include "sim_common.hpp"

namespace edgefem::cli {

namespace {

struct SimulateOptions {
    std::string scene;  // empty: the built-in default
    std::string out;    // overrides output.dir
    int steps = -1;     // >= 0 overrides the scene's steps
    std::string integrator;  // non-empty overrides the scene's integrator
    std::string preconditioner;  // non-empty overrides solver.preconditioner
    std::string checkpoint;      // written every checkpoint_every steps and at the end
    long checkpoint_every = 0;   // 0: only at the end
    std::string restart;         // a checkpoint to resume from
    std::string format;          // non-empty overrides output.format
    bool quiet = false;          // no progress on stderr
    // Its ordering is the internal vertex numbering: RCM by default (the
    // force on bunny-1m runs 2-2.5x faster than in TetGen's numbering:
    // docs/layouts.md, "Orderings: bunny-1m force, 1 thread"); frames and
    // messages stay in the mesh's numbering.
    RunOptions run;
};

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A bar redrawn in place on a terminal; otherwise a line every 10%, so logs
// stay short.
class Progress {
public:
    explicit Progress(long total) : total_(total), tty_(::isatty(::fileno(stderr)) == 1) {}

    void update(long done, double ms_per_step) {
        if (total_ <= 0) return;
        if (tty_) {
            if (100 * done / total_ == last_percent_ && done != total_) return;  // redraw only on change
            last_percent_ = 100 * done / total_;
            const int width = 40, filled = int(width * done / total_);
            std::fprintf(stderr, "\r[%s%s] %3ld%% step %ld/%ld %.3g ms/step", std::string(filled, '#').c_str(),
                         std::string(width - filled, ' ').c_str(), 100 * done / total_, done, total_, ms_per_step);
            open_ = true;
            if (done == total_) finish();
        } else if (const long decile = 10 * done / total_; decile > last_decile_) {
            last_decile_ = decile;
            std::fprintf(stderr, "edgefem: step %ld/%ld (%ld%%)\n", done, total_, 10 * decile);
        }
    }
    // Ends the bar's line (before an error message or the summary).
    void finish() {
        if (open_) std::fputc('\n', stderr);
        open_ = false;
    }

private:
    long total_;
    bool tty_;
    bool open_ = false;
    long last_decile_ = 0;
    long last_percent_ = -1;
};

void run_simulate(const SimulateOptions& opts) {
    using clock = std::chrono::steady_clock;
    const auto t_start = clock::now();
    SceneFile sf = load_scene_file(opts.scene);
    // A scene stays under the current folder; --out may name any folder.
    if (opts.out.empty())
        check_scene_output_dir(sf.output.dir, sf.path.empty() ? "the built-in scene" : sf.path);
    else
        sf.output.dir = opts.out;
    if (opts.steps >= 0) sf.scene.steps = opts.steps;
    if (!opts.integrator.empty()) {
        for (const auto& [name, value] : integrator_names())
            if (opts.integrator == name) sf.scene.integrator = value;
        sf.scene.validate();  // settings the new integrator does not take are errors
    }
    if (!opts.preconditioner.empty())
        sf.scene.solver.preconditioner = parse_preconditioner(opts.preconditioner, "--preconditioner");
    if (!opts.format.empty()) sf.output.format = parse_output_format(opts.format, sf.output.mesh, "--format");
    const OutputSettings out = sf.output;
    const bool vtu = out.format == OutputFormat::Binary || out.format == OutputFormat::Ascii;  // PLY, OBJ: no .pvd
    const std::string name = sf.path.empty() ? "default" : std::filesystem::path(sf.path).stem().string();

    const auto executor = make_run_executor(opts.run);
    OrderedSimulator<double> osim(sf.scene, parse_ordering(opts.run.ordering),
                                  make_run_backend<double>(opts.run, executor));
    Simulator<double>& sim = osim.internal();
    const Scene& scene = sf.scene;  // the user's numbering
    // A restart continues the scene's run from the checkpoint's step: the
    // remaining steps, frames numbered by the step as before.
    if (!opts.restart.empty()) osim.load_checkpoint(opts.restart);
    const long first_step = sim.step_index();
    const long steps = std::max(0L, scene.steps - first_step);
    const auto save_checkpoint = [&] {
        check_replaceable(opts.checkpoint, kCheckpointSignature);
        osim.save_checkpoint(opts.checkpoint);
    };
    if (!opts.checkpoint.empty()) check_replaceable(opts.checkpoint, kCheckpointSignature);  // before the run

    std::optional<FrameWriter> frames;
    std::optional<PvdSeries> series;
    if (out.vtu) {
        make_output_dir(out.dir, opts.out.empty() ? "output.dir" : "--out");
        frames.emplace(scene, out, sf.file_vertex);
        const std::string pvd = (std::filesystem::path(out.dir) / (name + ".pvd")).string();
        if (vtu) {
            check_replaceable(pvd, kPvdSignature);
            series.emplace(pvd);
            // A restart's series lists the frames of the run before it (those
            // of its output steps that are in the folder), at the times that
            // run had (its time is summed step by step, as here).
            double t = 0;
            for (long s = 0; s <= first_step && first_step > 0; t += scene.dt, ++s) {
                if (s % out.every != 0 && s != first_step) continue;
                char frame[64];
                std::snprintf(frame, sizeof frame, "_%06ld.vtu", s);
                const std::string path = (std::filesystem::path(out.dir) / (name + frame)).string();
                if (std::filesystem::is_regular_file(path)) series->add(t, path);
            }
        }
        // Compaction renumbered the vertices: the map back to the file's numbering.
        if (!sf.file_vertex.empty()) {
            const std::string map = (std::filesystem::path(out.dir) / (name + ".vertex-map")).string();
            check_replaceable(map, kVertexMapSignature);
            write_vertex_map(map, sf.file_vertex);
        }
    }
    char frame_name[64];
    std::vector<double> u_user(3 * std::size_t(scene.mesh.num_vertices())), v_user(u_user.size()),
        f_user(u_user.size());
    const auto write_frame = [&] {
        if (!frames) return;
        std::snprintf(frame_name, sizeof frame_name, "_%06ld%s", sim.step_index(), frames->extension());
        const std::string path = (std::filesystem::path(out.dir) / (name + frame_name)).string();
        osim.get_displacement(u_user);
        osim.get_velocity(v_user);
        osim.get_forces(f_user);
        check_replaceable(path, frame_signature(out.format));
        frames->write(path, u_user, v_user, f_user);
        if (!series) return;
        series->add(sim.time(), path);
        series->write();  // a crash later still leaves a usable series
    };

    // Total energy at the start, at every output step and at the end: its
    // drift is measured against the energy that moves around (kinetic +
    // elastic), since the gravity potential's zero is arbitrary.
    const Energies e0 = sim.energies();
    double e_scale = std::abs(e0.total()), e_last = e0.total();
    const auto sample_energy = [&] {
        const Energies e = sim.energies();
        e_scale = std::max(e_scale, e.kinetic + e.elastic);
        e_last = e.total();
    };

    std::vector<double> step_ms, force_ms, stiffness_ms, solve_ms;
    long cg_total = 0;
    int cg_max = 0;
    index_t inverted_max = 0;
    long inverted_steps = 0, first_inverted_step = 0;
    long unconverged_steps = 0;  // CG stopped above its tolerance
    long halved_steps = 0, step_halvings = 0;  // steps run in pieces (solver.max_step_halvings), failed pieces
    Progress progress(opts.quiet ? 0 : steps);
    if (first_step == 0) write_frame();  // a restart's was written by the run before it
    try {
        for (long s = 1; s <= steps; ++s) {
            const auto t0 = clock::now();
            const StepStats& st = osim.step();
            step_ms.push_back(std::chrono::duration<double, std::milli>(clock::now() - t0).count());
            force_ms.push_back(st.force_ms);
            stiffness_ms.push_back(st.stiffness_ms);
            solve_ms.push_back(st.solve_ms);
            cg_total += st.solver_iterations;
            cg_max = std::max(cg_max, st.solver_iterations);
            inverted_max = std::max(inverted_max, st.inverted_tets);
            if (st.inverted_tets > 0 && inverted_steps++ == 0) first_inverted_step = s;
            unconverged_steps += st.unconverged_solves > 0;
            halved_steps += st.substep_depth > 0;
            step_halvings += st.halvings;
            const long step = first_step + s;  // the scene's step number
            if (step % out.every == 0 || s == steps) {
                write_frame();
                sample_energy();
            }
            if (!opts.checkpoint.empty() && opts.checkpoint_every > 0 && step % opts.checkpoint_every == 0 &&
                s != steps)
                save_checkpoint();
            progress.update(s, step_ms.back());
        }
    } catch (const SimulationError&) {
        progress.finish();
        throw;
    }

    if (!opts.checkpoint.empty()) save_checkpoint();

    // Said once, not per step: a run full of inverted tets looks like a
    // success otherwise (exit 0, one number in the summary).
    if (inverted_steps > 0)
        std::fprintf(stderr,
                     "edgefem: warning: %ld of %ld steps ended with inverted tets (negative volume; at most %ld of "
                     "%ld tets, first at step %ld): the results past that step are suspect "
                     "(solver.fail_on_inverted makes this an error)\n",
                     inverted_steps, steps, long(inverted_max), long(scene.mesh.num_tets()), first_inverted_step);
    const double e_drift = e_scale > 0 ? (e_last - e0.total()) / e_scale : 0.0;
    print_kv("scene", sf.path.empty() ? std::string("default (built-in beam)") : sf.path);
    print_kv("vertices", scene.mesh.num_vertices());
    print_kv("tets", scene.mesh.num_tets());
    print_kv("integrator", to_string(scene.integrator));
    print_kv("ordering", opts.run.ordering);
    print_kv("backend", describe(opts.run, executor.get()));
    print_kv("steps", steps);
    if (first_step > 0) print_kv("restarted_at_step", first_step);
    if (!opts.checkpoint.empty()) print_kv("checkpoint", opts.checkpoint);
    print_kv("ms_per_step", fmt(median(step_ms), 6));
    print_kv("force_ms", fmt(median(force_ms), 6));
    print_kv("stiffness_ms", fmt(median(stiffness_ms), 6));
    print_kv("solve_ms", fmt(median(solve_ms), 6));
    print_kv("cg_iterations_mean", fmt(steps > 0 ? double(cg_total) / double(steps) : 0.0, 6));
    print_kv("cg_iterations_max", cg_max);
    print_kv("unconverged_steps", unconverged_steps);
    print_kv("halved_steps", halved_steps);
    print_kv("step_halvings", step_halvings);
    print_kv("energy_drift", fmt(e_drift, 6));
    print_kv("inverted_tets", inverted_max);
    if (out.vtu)
        print_kv("output", (std::filesystem::path(out.dir) / (vtu ? name + ".pvd" : name + "_*" + file_extension(out.format)))
                               .string());
    if (executor) print_adaptive(*executor);
    print_kv("wall_s", fmt(std::chrono::duration<double>(clock::now() - t_start).count(), 6));
}

}  // namespace

void add_simulate_command(CLI::App& app) {
    auto opts = std::make_shared<SimulateOptions>();
    auto* cmd = app.add_subcommand(
        "simulate",
        "Step a scene (docs/scenes.md; without SCENE the built-in beam: 19,200 tets, clamped at one end, "
        "sagging under gravity, 1000 semi-implicit steps of 1 ms). Writes OUT/<scene>_<step>.vtu frames "
        "(by default compressed binary: displacement, velocity, internal force, energy density, von Mises "
        "stress; output.* in docs/scenes.md) every output.every steps and OUT/<scene>.pvd; "
        "shows progress on stderr; prints median timings per step, CG iterations, the energy drift "
        "(last - first total energy, relative to the largest kinetic + elastic energy seen) and the "
        "most inverted tets in any step");
    // An empty SCENE or --out would silently mean the built-in beam or the
    // scene's folder.
    cmd->add_option("SCENE", opts->scene, "Scene file (JSON, see docs/scenes.md); default: the built-in beam")
        ->check(non_empty_path());
    cmd->add_option("--out", opts->out, "Output folder (overrides the scene's output.dir; default edgefem-out)")
        ->check(non_empty_path());
    cmd->add_option("--steps", opts->steps, "Number of steps (overrides the scene's steps)")
        ->check(int_in_range(0));
    std::vector<std::string> integrators;
    for (const auto& [name, value] : integrator_names()) integrators.push_back(name);
    cmd->add_option("--integrator", opts->integrator, "Time integrator (overrides the scene's; docs/dynamics.md)")
        ->check(CLI::IsMember(integrators));
    cmd->add_option("--preconditioner", opts->preconditioner,
                    "CG's preconditioner: auto (block-Jacobi, AMG once a solve needs more than solver.auto_amg_iterations, back where AMG costs more), block-jacobi or amg (overrides the scene's solver.preconditioner; "
                    "docs/solvers.md)");
    cmd->add_option("--checkpoint", opts->checkpoint,
                    "Write a checkpoint (the whole state, docs/api.md \"Checkpoints\") to this file at the end "
                    "and every --checkpoint-every steps, replacing the last")
        ->check(non_empty_path());
    cmd->add_option("--checkpoint-every", opts->checkpoint_every, "Steps between checkpoints (needs --checkpoint)")
        ->check(int_in_range(1));
    cmd->add_option("--restart", opts->restart,
                    "Resume from a checkpoint of this scene (same integrator, solver and --ordering): steps on "
                    "from its step to the scene's last, bitwise as if the run had not stopped")
        ->check(CLI::ExistingFile);
    cmd->add_option("--format", opts->format,
                    "Frame format: binary (compressed VTU), ascii (VTU), ply or obj (with output.mesh \"surface\"); "
                    "overrides the scene's output.format (docs/scenes.md)");
    cmd->add_flag("--quiet", opts->quiet, "No progress on stderr");
    cmd->footer(kExitCodesHelp);
    add_ordering_option(*cmd, opts->run.ordering);
    add_run_options(*cmd, opts->run);
    cmd->callback([opts] {
        if (opts->checkpoint_every > 0 && opts->checkpoint.empty())
            throw InvalidArgument("--checkpoint-every needs --checkpoint FILE");
        run_simulate(*opts);
    });
}

}  // namespace edgefem::cli
