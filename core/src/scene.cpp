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
    for (const auto& [name, value] : integrator_names())
        if (value == i) return name;
    return "unknown";
}

const std::vector<std::pair<const char*, Integrator>>& integrator_names() {
    static const std::vector<std::pair<const char*, Integrator>> names{
        {"explicit", Integrator::Explicit},
        {"semi-implicit", Integrator::SemiImplicit},
        {"implicit", Integrator::Implicit},
        {"newmark", Integrator::Newmark},
        {"newmark-linear", Integrator::NewmarkLinear},
        {"generalized-alpha", Integrator::GeneralizedAlpha},
        {"generalized-alpha-linear", Integrator::GeneralizedAlphaLinear},
        {"bdf2", Integrator::Bdf2},
        {"bdf2-linear", Integrator::Bdf2Linear},
        {"verlet", Integrator::Verlet},
    };
    return names;
}

bool is_linearised(Integrator i) {
    return i == Integrator::SemiImplicit || i == Integrator::NewmarkLinear || i == Integrator::GeneralizedAlphaLinear ||
           i == Integrator::Bdf2Linear;
}

bool is_explicit(Integrator i) { return i == Integrator::Explicit || i == Integrator::Verlet; }

const char* to_string(LinearSolver s) { return s == LinearSolver::CG ? "cg" : "direct"; }

double keyframe_value(const std::vector<Keyframe>& keys, double t) {
    if (keys.empty()) return 1;
    if (t <= keys.front().time) return keys.front().value;
    for (std::size_t k = 1; k < keys.size(); ++k)
        if (t <= keys[k].time) {
            const Keyframe &a = keys[k - 1], &b = keys[k];
            return a.value + (b.value - a.value) * (t - a.time) / (b.time - a.time);
        }
    return keys.back().value;
}

namespace {
void check_keyframes(const std::string& field, const std::vector<Keyframe>& keys) {
    for (std::size_t k = 0; k < keys.size(); ++k) {
        const std::string f = field + "[" + std::to_string(k) + "]";
        if (!std::isfinite(keys[k].time) || !std::isfinite(keys[k].value)) bad(f, "non-finite time or value");
        if (k > 0 && !(keys[k].time > keys[k - 1].time)) bad(f, "times must increase strictly");
    }
}
void check_per_dof(const std::string& field, const std::vector<double>& x, std::size_t nd) {
    if (x.empty()) return;
    if (x.size() != nd)
        bad(field, "expected 3 x #V = " + std::to_string(nd) + " values, got " + std::to_string(x.size()));
    for (std::size_t i = 0; i < x.size(); ++i)
        if (!std::isfinite(x[i])) bad(field, "non-finite value at vertex " + std::to_string(i / 3));
}
}  // namespace

const char* to_string(PreconditionerKind p) {
    return p == PreconditionerKind::Amg ? "amg" : p == PreconditionerKind::Auto ? "auto" : "block-jacobi";
}

PreconditionerKind parse_preconditioner(const std::string& name, const std::string& key) {
    if (name == "auto") return PreconditionerKind::Auto;
    if (name == "block-jacobi") return PreconditionerKind::BlockJacobi;
    if (name == "amg") return PreconditionerKind::Amg;
    throw InvalidArgument(key + ": expected one of \"auto\", \"block-jacobi\", \"amg\", got \"" + name + "\"");
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
                bad("mesh", mesh.describe_vertex(v) + " is used by no tet (it would have no mass); remove the vertices "
                    "no tet uses from the mesh (in C++: validate_mesh with ValidationOptions::compact_unreferenced)");
    }
    // Enums that came in as integers (bindings, casts) must name a value.
    if (model != ModelKind::FE && model != ModelKind::SN) bad("model", "not a model (fe or sn)");
    if (method != Method::Edge && method != Method::Tet) bad("method", "not a method (edge or tet)");
    if (std::string(to_string(integrator)) == "unknown") {
        std::string list;
        for (const auto& [name, value] : integrator_names()) list += (list.empty() ? "" : ", ") + std::string(name);
        bad("integrator", "not an integrator (" + list + ")");
    }
    const IntegratorParameters& ip = integrator_parameters;
    if (!(ip.newmark_beta > 0 && ip.newmark_beta <= 0.5))
        bad("newmark.beta", "must lie in (0, 1/2], got " + std::to_string(ip.newmark_beta));
    if (!(ip.newmark_gamma >= 0.5 && ip.newmark_gamma <= 1))
        bad("newmark.gamma", "must lie in [1/2, 1], got " + std::to_string(ip.newmark_gamma));
    if (!(ip.rho_inf >= 0 && ip.rho_inf <= 1))
        bad("generalized_alpha.rho_inf", "must lie in [0, 1], got " + std::to_string(ip.rho_inf));
    if (solver.linear_solver != LinearSolver::CG && solver.linear_solver != LinearSolver::Direct)
        bad("solver.linear_solver", "not a linear solver (cg or direct)");
    if (solver.preconditioner != PreconditionerKind::BlockJacobi && solver.preconditioner != PreconditionerKind::Amg &&
        solver.preconditioner != PreconditionerKind::Auto)
        bad("solver.preconditioner", "not a preconditioner (auto, block-jacobi or amg)");
    if (solver.auto_amg_iterations < 1)
        bad("solver.auto_amg_iterations", "must be >= 1, got " + std::to_string(solver.auto_amg_iterations));
    if (solver.amg_refresh_interval < 0) bad("solver.amg_refresh_interval", "must be >= 0 (0: adaptive)");
    materials.validate();
    for (int r = 0; r < 3; ++r)
        if (!std::isfinite(gravity[r])) bad("gravity", "non-finite component");
    non_negative("damping.alpha", rayleigh_alpha);
    non_negative("damping.beta", rayleigh_beta);
    if (rayleigh_beta > 0 && integrator == Integrator::Verlet)
        bad("damping.beta", "stiffness-proportional damping needs the explicit (symplectic Euler) or an implicit "
                            "integrator (verlet never builds K)");
    if (model == ModelKind::SN && method == Method::Tet) bad("model", "the spring network exists only for the edge method");
    if (solver.definite_stiffness && method == Method::Tet)
        bad("solver.definite_stiffness", "the definite tangent exists only for the edge method");
    positive("dt", dt);
    if (steps < 0) bad("steps", "must be >= 0");
    if (prescribed_steps < 1) bad("prescribed.steps", "must be >= 1");
    check_keyframes("prescribed.keyframes", prescribed_keyframes);
    check_keyframes("load.keyframes", load_keyframes);
    const std::size_t nd = 3 * std::size_t(nv);
    check_per_dof("load", load, nd);
    check_per_dof("initial.displacement", initial_displacement, nd);
    check_per_dof("initial.velocity", initial_velocity, nd);
    if (!load_keyframes.empty() && load.empty()) bad("load.keyframes", "keyframes without a load");
    for (std::size_t i = 0; i < surface_loads.size(); ++i) {
        const SurfaceLoad& sl = surface_loads[i];
        const std::string field = "surface_loads[" + std::to_string(i) + "]";
        if (sl.triangles.empty()) bad(field + ".triangles", "no triangles");
        for (std::size_t k = 0; k < sl.triangles.size(); ++k)
            for (const index_t v : sl.triangles[k])
                if (v < 0 || v >= nv)
                    bad(field + ".triangles[" + std::to_string(k) + "]",
                        "vertex " + std::to_string(v) + " out of range (mesh has " + std::to_string(nv) + " vertices)");
        if (!std::isfinite(sl.pressure)) bad(field + ".pressure", "non-finite value");
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(sl.traction[r])) bad(field + ".traction", "non-finite component");
        check_keyframes(field + ".keyframes", sl.keyframes);
    }
    positive("solver.cg_tolerance", solver.cg_tolerance);
    if (solver.cg_max_iterations < 1) bad("solver.cg_max_iterations", "must be >= 1");
    if (solver.cg_fixed_iterations < 0) bad("solver.cg_fixed_iterations", "must be >= 0");
    positive("solver.newton_tolerance", solver.newton_tolerance);
    if (solver.newton_max_iterations < 1) bad("solver.newton_max_iterations", "must be >= 1");
    if (solver.load_steps < 1) bad("solver.load_steps", "must be >= 1");
    if (solver.max_step_halvings < 0 || solver.max_step_halvings > 30)
        bad("solver.max_step_halvings", "must be in [0, 30]");
    if (solver.stiffness_interval < 1) bad("solver.stiffness_interval", "must be >= 1");
    // Settings that only the linearised steps with CG read: elsewhere they
    // were accepted and silently ignored.
    const bool semi_cg = integrator == Integrator::SemiImplicit && solver.linear_solver == LinearSolver::CG;
    const bool linear_cg = is_linearised(integrator) && solver.linear_solver == LinearSolver::CG;
    if (solver.stiffness_interval > 1 && !semi_cg)
        bad("solver.stiffness_interval", "> 1 applies only to the semi-implicit integrator with the cg solver");
    if (solver.cg_fixed_iterations > 0 && !linear_cg)
        bad("solver.cg_fixed_iterations",
            "> 0 applies only to the linearised integrators (semi-implicit, newmark-linear, generalized-alpha-linear, "
            "bdf2-linear) with the cg solver (Newton's solves run to their tolerance)");
    if (!std::isfinite(solver.max_energy_growth) || (solver.max_energy_growth != 0 && !(solver.max_energy_growth >= 1)))
        bad("solver.max_energy_growth", "must be 0 (off) or a finite number >= 1, got " + std::to_string(solver.max_energy_growth));
    if (solver.fail_on_inverted && !count_inverted_tets)
        bad("solver.fail_on_inverted", "needs count_inverted_tets (the inverted tets are not counted otherwise)");
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
