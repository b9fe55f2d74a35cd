// `edgefem forces MESH ...`: energy, nodal forces and optionally K times a
// direction at one configuration, written as text files.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common.hpp"
#include "edgefem/core/deformations.hpp"

namespace edgefem::cli {

namespace {

struct ForcesOptions {
    MeshOptions mesh;
    ModelOptions model;
    ExecOptions exec;
    std::string pos, dir, deform, out;
};

void run_forces(const ForcesOptions& opts) {
    opts.model.validate();
    const LoadedMesh lm = load_mesh(opts.mesh);
    const Mesh& mesh = lm.user_mesh();  // inputs and outputs use the mesh's own numbering
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

    write_scalar(opts.out + ".energy", energy);
    write_vectors(opts.out + ".force", f);
    if (!opts.deform.empty()) write_vectors(opts.out + ".pos", positions_from_displacement(mesh, u));
    if (!dir.empty()) {
        std::vector<double> Kd;
        eval->stiffness_times(lm.to_internal(dir), Kd);
        write_vectors(opts.out + ".Kdir", lm.to_user(Kd));
    }

    double max_force = 0;  // largest nodal force magnitude
    for (std::size_t i = 0; i + 2 < f.size(); i += 3)
        max_force = std::max(max_force, std::sqrt(f[i] * f[i] + f[i + 1] * f[i + 1] + f[i + 2] * f[i + 2]));
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
