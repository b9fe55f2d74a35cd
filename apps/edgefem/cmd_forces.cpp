// `edgefem forces MESH ...`: energy, nodal forces and optionally K times a
// direction at one configuration, written as text files.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common.hpp"
#include "lab/deformations.hpp"
#include "edgefem/core/simulator.hpp"

namespace edgefem::cli {

namespace {

struct ForcesOptions {
    MeshOptions mesh;
    ModelOptions model;
    ExecOptions exec;
    std::string pos, dir, deform, out;
};

// The first vertex with a non-finite component of `v` (3 per vertex), or -1.
std::int64_t first_non_finite(const std::vector<double>& v) {
    for (std::size_t i = 0; i < v.size(); ++i)
        if (!std::isfinite(v[i])) return std::int64_t(i / 3);
    return -1;
}

void run_forces(const ForcesOptions& opts) {
    opts.model.validate();
    const LoadedMesh lm = load_mesh(opts.mesh);
    const Mesh& mesh = lm.user_mesh();  // inputs and outputs use the mesh's own numbering
    check_mesh_scale(mesh, opts.model.precision_kind(), opts.mesh.path);
    for (const auto& w : load_warnings(lm)) std::fprintf(stderr, "edgefem: warning: %s\n", w.c_str());
    const index_t nv = mesh.num_vertices();

    // The configuration as a displacement, formed in double.
    std::vector<double> u(3 * std::size_t(nv), 0.0);
    if (!opts.deform.empty()) {
        u = deformation_displacement(mesh, parse_deformation(opts.deform));
    } else if (!opts.pos.empty()) {
        const std::vector<double> x = read_vectors(opts.pos, nv);
        for (std::size_t i = 0; i < u.size(); ++i) u[i] = x[i] - mesh.X[i];
    }
    // Read every input before writing any output.
    std::vector<double> dir;
    if (!opts.dir.empty()) dir = read_vectors(opts.dir, nv);

    auto eval = make_evaluator(lm.mesh, opts.model, opts.exec);
    eval->set_displacement(lm.to_internal(u));
    std::vector<double> f;
    const auto t0 = std::chrono::steady_clock::now();
    const double energy = eval->energy_forces(f);
    const auto t1 = std::chrono::steady_clock::now();
    f = lm.to_user(f);
    std::vector<double> Kd;
    if (!dir.empty()) {
        eval->stiffness_times(lm.to_internal(dir), Kd);
        Kd = lm.to_user(Kd);
    }

    // Values past the chosen precision's range come out as inf or NaN
    // without any error from the kernels: refuse to write them.
    const std::string cause = " is not finite: the computation left the range of " + opts.model.precision +
                              " precision (check the mesh's scale, the material and the positions)";
    if (!std::isfinite(energy)) throw SimulationError("forces: the energy (" + fmt(energy) + ")" + cause, 0);
    if (const auto v = first_non_finite(f); v >= 0)
        throw SimulationError("forces: the force at vertex " + std::to_string(v) + " (0-based)" + cause, 0, index_t(v));
    if (const auto v = first_non_finite(Kd); v >= 0)
        throw SimulationError("forces: K dir at vertex " + std::to_string(v) + " (0-based)" +
                                  cause.substr(0, cause.size() - 1) + ", and --dir's values)", 0, index_t(v));

    write_scalar(opts.out + ".energy", energy);
    write_vectors(opts.out + ".force", f);
    if (!opts.deform.empty()) write_vectors(opts.out + ".pos", positions_from_displacement(mesh, u));
    if (!dir.empty()) write_vectors(opts.out + ".Kdir", Kd);

    double max_force = 0;  // largest nodal force magnitude
    for (std::size_t i = 0; i + 2 < f.size(); i += 3) {
        // hypot: no overflow of the squares; !(<=) would also take a NaN.
        const double m = std::hypot(f[i], f[i + 1], f[i + 2]);
        if (!(m <= max_force)) max_force = m;
    }
    print_kv("energy", energy);
    print_kv("max_force", max_force);
    print_kv("time_ms", fmt(std::chrono::duration<double, std::milli>(t1 - t0).count(), 6));
}

}  // namespace

void add_forces_command(CLI::App& app) {
    auto opts = std::make_shared<ForcesOptions>();
    auto* cmd = app.add_subcommand(
        "forces",
        "Evaluate energy and nodal forces (and K times a direction) at one configuration; writes "
        "PREFIX.energy, PREFIX.force, PREFIX.Kdir (with --dir) and PREFIX.pos (with --deform), %.17g");
    opts->mesh.ordering = "rcm";  // the measured winner (docs/layouts.md), as simulate and static
    add_mesh_options(*cmd, opts->mesh);
    add_model_options(*cmd, opts->model, /*material_required=*/true);
    add_exec_options(*cmd, opts->exec);
    // Empty paths would be taken as "not given" (--pos, --dir) or write
    // hidden files (--out "": .energy, .force).
    auto* pos = cmd->add_option("--pos", opts->pos, "Current positions: one 'x y z' line per vertex (default: rest shape)")
                    ->check(non_empty_path());
    cmd->add_option("--dir", opts->dir, "Direction vector, one 'x y z' line per vertex: also write PREFIX.Kdir = K dir")
        ->check(non_empty_path());
    cmd->add_option("--deform", opts->deform, "Generate the configuration instead of --pos (also writes PREFIX.pos)")
        ->check(CLI::IsMember({"twist", "rotate", "random", "affine"}))
        ->excludes(pos);
    cmd->add_option("--out", opts->out, "Output file prefix")->required()->check(non_empty_path());
    cmd->callback([opts] { run_forces(*opts); });
}

}  // namespace edgefem::cli
