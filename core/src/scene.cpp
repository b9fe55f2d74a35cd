#include "edgefem/core/scene.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/validate_mesh.hpp"

namespace edgefem {

namespace {
[[noreturn]] void bad(const std::string& field, const std::string& what) {
    throw InvalidArgument("scene: \"" + field + "\": " + what);
}
void positive(const std::string& field, double v) {
    if (!std::isfinite(v) || v <= 0) bad(field, "expected a positive finite number, got " + std::to_string(v));
}
void non_negative(const std::string& field, double v) {
    if (!std::isfinite(v) || v < 0) bad(field, "expected a non-negative finite number, got " + std::to_string(v));
}
}  // namespace

const char* to_string(Integrator i) {
    switch (i) {
        case Integrator::Explicit: return "explicit";
        case Integrator::SemiImplicit: return "semi-implicit";
        default: return "implicit";
    }
}

const char* to_string(LinearSolver s) { return s == LinearSolver::CG ? "cg" : "direct"; }

const char* to_string(PreconditionerKind p) { return p == PreconditionerKind::Amg ? "amg" : "block-jacobi"; }

PreconditionerKind parse_preconditioner(const std::string& name, const std::string& key) {
    if (name == "block-jacobi") return PreconditionerKind::BlockJacobi;
    if (name == "amg") return PreconditionerKind::Amg;
    throw InvalidArgument(key + ": expected one of \"block-jacobi\", \"amg\", got \"" + name + "\"");
}

void Scene::validate() const {
    const index_t nv = mesh.num_vertices();
    if (mesh.num_tets() == 0) bad("mesh", "the mesh has no tets");
    // A Scene may be filled in by hand (or through a foreign-language
    // binding), so the mesh is checked here, not only where files are read:
    // an index out of range would otherwise reach the topology build.
    check_mesh(mesh);
    // A vertex no tet uses has no mass: the Simulator cannot move it. Said
    // here, on the scene as given, so the message keeps the user's (and the
    // file's) numbering; the Simulator found it only after renumbering.
    {
        std::vector<char> used(nv, 0);
        for (const index_t v : mesh.tets) used[v] = 1;
        for (index_t v = 0; v < nv; ++v)
            if (!used[v])
                bad("mesh", mesh.describe_vertex(v) + " is used by no tet (it would have no mass); remove unreferenced "
                    "vertices with the compact option (ValidationOptions::compact_unreferenced, CLI --compact, "
                    "scene mesh_options.compact)");
    }
    // Enums that came in as integers (bindings, casts) must name a value.
    if (model != ModelKind::FE && model != ModelKind::SN) bad("model", "not a model (fe or sn)");
    if (method != Method::Edge && method != Method::Tet) bad("method", "not a method (edge or tet)");
    if (integrator != Integrator::Explicit && integrator != Integrator::SemiImplicit &&
        integrator != Integrator::Implicit)
        bad("integrator", "not an integrator (explicit, semi-implicit or implicit)");
    if (solver.linear_solver != LinearSolver::CG && solver.linear_solver != LinearSolver::Direct)
        bad("solver.linear_solver", "not a linear solver (cg or direct)");
    if (solver.preconditioner != PreconditionerKind::BlockJacobi && solver.preconditioner != PreconditionerKind::Amg)
        bad("solver.preconditioner", "not a preconditioner (block-jacobi or amg)");
    if (solver.amg_refresh_interval < 0) bad("solver.amg_refresh_interval", "must be >= 0 (0: adaptive)");
    materials.validate();
    for (int r = 0; r < 3; ++r)
        if (!std::isfinite(gravity[r])) bad("gravity", "non-finite component");
    non_negative("damping.alpha", rayleigh_alpha);
    non_negative("damping.beta", rayleigh_beta);
    if (rayleigh_beta > 0 && integrator == Integrator::Explicit)
        bad("damping.beta", "stiffness-proportional damping needs an implicit integrator (explicit steps never build K)");
    if (model == ModelKind::SN && method == Method::Tet) bad("model", "the spring network exists only for the edge method");
    if (solver.definite_stiffness && method == Method::Tet)
        bad("solver.definite_stiffness", "the definite tangent exists only for the edge method");
    positive("dt", dt);
    if (steps < 0) bad("steps", "must be >= 0");
    if (prescribed_steps < 1) bad("prescribed.steps", "must be >= 1");
    positive("solver.cg_tolerance", solver.cg_tolerance);
    if (solver.cg_max_iterations < 1) bad("solver.cg_max_iterations", "must be >= 1");
    if (solver.cg_fixed_iterations < 0) bad("solver.cg_fixed_iterations", "must be >= 0");
    positive("solver.newton_tolerance", solver.newton_tolerance);
    if (solver.newton_max_iterations < 1) bad("solver.newton_max_iterations", "must be >= 1");
    if (solver.load_steps < 1) bad("solver.load_steps", "must be >= 1");
    if (solver.max_step_halvings < 0) bad("solver.max_step_halvings", "must be >= 0");
    if (solver.stiffness_interval < 1) bad("solver.stiffness_interval", "must be >= 1");
    // Settings that only the semi-implicit step with CG reads: elsewhere
    // they were accepted and silently ignored.
    const bool semi_cg = integrator == Integrator::SemiImplicit && solver.linear_solver == LinearSolver::CG;
    if (solver.stiffness_interval > 1 && !semi_cg)
        bad("solver.stiffness_interval", "> 1 applies only to the semi-implicit integrator with the cg solver");
    if (solver.cg_fixed_iterations > 0 && !semi_cg)
        bad("solver.cg_fixed_iterations",
            "> 0 applies only to the semi-implicit integrator with the cg solver (Newton's solves run to their tolerance)");
    if (!std::isfinite(solver.max_energy_growth) || (solver.max_energy_growth != 0 && !(solver.max_energy_growth >= 1)))
        bad("solver.max_energy_growth", "must be 0 (off) or a finite number >= 1, got " + std::to_string(solver.max_energy_growth));
    std::vector<char> seen(nv, 0);
    for (std::size_t i = 0; i < fixed.size(); ++i) {
        if (fixed[i] < 0 || fixed[i] >= nv)
            bad("fixed[" + std::to_string(i) + "]", "vertex " + std::to_string(fixed[i]) + " out of range (mesh has " +
                                                      std::to_string(nv) + " vertices)");
        seen[fixed[i]] = 1;
    }
    for (std::size_t i = 0; i < prescribed.size(); ++i) {
        const auto& p = prescribed[i];
        const std::string field = "prescribed[" + std::to_string(i) + "]";
        if (p.vertex < 0 || p.vertex >= nv)
            bad(field, "vertex " + std::to_string(p.vertex) + " out of range (mesh has " + std::to_string(nv) + " vertices)");
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(p.target[r])) bad(field, "non-finite target");
        if (seen[p.vertex] == 2) bad(field, "vertex " + std::to_string(p.vertex) + " prescribed twice");
        if (seen[p.vertex] == 1) bad(field, "vertex " + std::to_string(p.vertex) + " is also fixed");
        seen[p.vertex] = 2;
    }
}

}  // namespace edgefem
