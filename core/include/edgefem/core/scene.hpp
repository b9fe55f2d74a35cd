// A simulation scene: what is simulated (mesh, materials, model), what acts
// on it (gravity, damping, fixed and prescribed vertices) and how it is
// stepped (integrator, time step, solver settings). Plain data; validate()
// checks it and names the offending field.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "edgefem/core/amg_settings.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem {

enum class Integrator {
    Explicit,      // symplectic Euler: builds K only for stiffness damping (beta)
    SemiImplicit,  // linearised backward Euler, one K per step, CG (the talk's form)
    Implicit,      // backward Euler solved by Newton with line search
    // Second order (docs/dynamics.md, "Integrators"). The implicit ones come
    // in two forms, as backward Euler: solved by Newton to tolerance, and
    // linearised at the step's start (one K per step, CG budgets allowed).
    Newmark,                 // Newmark-beta (beta = 1/4, gamma = 1/2: the trapezoidal rule), Newton
    NewmarkLinear,           // the same, linearised
    GeneralizedAlpha,        // Chung-Hulbert generalized-alpha (rho_inf), Newton
    GeneralizedAlphaLinear,  // the same, linearised
    Bdf2,                    // BDF2 (backward Euler on its first step and after a change of step size), Newton
    Bdf2Linear,              // the same, linearised
    Verlet,                  // velocity Verlet / central differences: explicit, never builds K
};

// Whether the integrator is one of the linearised forms (one K per step).
bool is_linearised(Integrator i);
// Whether it is explicit (never builds K).
bool is_explicit(Integrator i);

// The integrators' parameters.
struct IntegratorParameters {
    double newmark_beta = 0.25;  // Newmark: 0 < beta <= 1/2
    double newmark_gamma = 0.5;  // Newmark: 1/2 <= gamma <= 1 (1/2: second order)
    // Generalized-alpha: the spectral radius at infinite frequency, in [0, 1]
    // (1: no numerical damping, the trapezoidal rule; 0: the highest
    // frequencies annihilated in one step).
    double rho_inf = 0.8;
};

enum class LinearSolver {
    CG,      // matrix-free CG on the per-edge K (SolverSettings::preconditioner)
    Direct,  // assembled sparse K, CHOLMOD (supernodal LL^T, LDL^T when A is indefinite)
};

// CG's preconditioner (docs/solvers.md says when each is faster).
enum class PreconditionerKind {
    BlockJacobi,  // the inverse 3x3 diagonal blocks: cheap, iterations grow with dt, stiffness and mesh size
    Amg,          // smoothed-aggregation multigrid on the rigid-body modes: set-up per K, few iterations
    Auto,         // block-Jacobi, AMG from a solve that needs more than a threshold, back where AMG costs more (the default)
};

struct SolverSettings {
    LinearSolver linear_solver = LinearSolver::CG;
    PreconditionerKind preconditioner = PreconditionerKind::Auto;
    // Auto: the block-Jacobi CG iterations of one solve past which AMG takes
    // over (docs/solvers.md has the measured crossover), at first; where AMG
    // then costs more, block-Jacobi comes back with the AMG's cost as its
    // threshold (this one again after a wait of 8, 16, 32, ... set-ups where
    // the AMG's dear solves looked like a transient). Never with
    // cg_fixed_iterations, or off the host.
    int auto_amg_iterations = 60;
    // AMG: when its Galerkin operators and smoothers follow a new K (the
    // fine level's products are always the current K's). 0 (default): lagged
    // while CG's iterations per decade of residual reduction stay within
    // 1.5x (+ 2 iterations) of the solve's right after the last refresh, and
    // on every change of the step size; N >= 1: every N-th
    // K (1: every K) and on every change of the step size. docs/solvers.md
    // has the measurements.
    int amg_refresh_interval = 0;
    AmgSettings amg;  // the hierarchy and smoother (amg_settings.hpp); C++ only
    double cg_tolerance = 1e-6;   // relative residual |r| / |b| of the projected system
    int cg_max_iterations = 500;
    int cg_fixed_iterations = 0;  // > 0: exactly this many warm-started iterations (haptic budget)
    // The linearised steps' CG to a tolerance starts from the step's
    // prediction improved along a direction from the history (semi-implicit
    // and BDF2: the last change of velocity; Newmark, generalized-alpha: the
    // acceleration), by the amount that lowers the error most; false: from
    // the prediction.
    bool warm_start = true;
    bool definite_stiffness = false;  // clamp g(E) at zero inside K (edge method)
    double newton_tolerance = 1e-10;  // relative residual for Implicit and static solves
    int newton_max_iterations = 50;
    int load_steps = 1;               // static: initial number of load steps (halved on failure)
    int max_step_halvings = 0;        // dynamics: retry a failed step with dt/2 up to this often
    // Semi-implicit with CG: build K (and its preconditioner) every this many
    // steps and reuse it in between: a lagged tangent, as haptic loops do to
    // fit their budget. 1 (default) builds K every step.
    int stiffness_interval = 1;
    // Semi-implicit with a CG tolerance: a solve that stops at
    // cg_max_iterations above the tolerance fails the step (SimulationError,
    // or a retry with max_step_halvings): the default, because the stress
    // suite showed such steps let the energy grow 100-3000x without an error
    // (Y = 1e9, 0.1-degree slivers). false only counts them in
    // StepStats::unconverged_solves. (A fixed CG budget,
    // cg_fixed_iterations, is a deliberate partial solve and never fails.)
    bool fail_on_unconverged = true;
    // Energy guard for the dynamic integrators: a step fails (SimulationError,
    // or a retry with max_step_halvings) when the total energy (kinetic +
    // elastic + gravity) has risen above its lowest level, net of the
    // external forces' work and of what mass damping removed, by more than
    // (max_energy_growth - 1) x the largest kinetic + elastic energy seen: a
    // body released at rest then never holds more than this factor of its
    // energy. Steps that move a constrained vertex are checked on the free
    // vertices, the constraints' work counted as supplied; linearised steps
    // with a fixed CG budget fail only past 1000x (a blow-up), a lesser gain
    // is measured (StepStats::energy_growth). 0 disables it; otherwise
    // >= 1. docs/scenes.md ("Solver settings") says why 10.
    double max_energy_growth = 10;
    // A step that ends with inverted tets (negative volume) fails with a
    // SimulationError instead of only being counted in
    // StepStats::inverted_tets (`edgefem static` fails the same way after
    // writing its files). Needs Scene::count_inverted_tets.
    bool fail_on_inverted = false;
};

// A value given at times (s), linear in between, constant before the first
// and after the last (keyframe_value).
struct Keyframe {
    double time, value;
};
double keyframe_value(const std::vector<Keyframe>& keys, double t);

// A vertex driven to a target position.
struct Prescribed {
    index_t vertex;
    std::array<double, 3> target;
};

// A pressure and a traction on a surface, dead loads on the rest
// configuration: the force of each triangle is computed once from its rest
// area and normal (it does not turn or grow with the deformed surface) and
// given to its three vertices in equal thirds (exact for a constant load on
// linear triangles). docs/scenes.md, "Surface loads".
struct SurfaceLoad {
    // Triangles wound so that (b - a) x (c - a) points out of the body
    // (select_surface's and boundary_surface's winding); mesh vertices.
    std::vector<std::array<index_t, 3>> triangles;
    // Pa, along the inward normal: a positive pressure pushes into the body
    // (force -p n A per triangle, n the outward unit normal, A its area).
    double pressure = 0;
    std::array<double, 3> traction{0, 0, 0};  // Pa: force per rest area, a fixed vector
    std::vector<Keyframe> keyframes;          // scale s(t), as load_keyframes (empty: 1)
};

struct Scene {
    Mesh mesh;
    Materials materials;
    ModelKind model = ModelKind::FE;
    Method method = Method::Edge;
    std::array<double, 3> gravity{0, 0, 0};  // m/s^2
    double rayleigh_alpha = 0;               // D = alpha M + beta K
    double rayleigh_beta = 0;                // not with verlet; explicit builds K for it
    std::vector<index_t> fixed;              // held at their rest position
    std::vector<Prescribed> prescribed;      // moved linearly from rest to target
    int prescribed_steps = 1;                // dynamics: steps over which targets are reached
    // Dynamics: the fraction of the prescribed displacements (target - rest)
    // at time t, piecewise linear (keyframe_value); empty: the linear ramp
    // over prescribed_steps.
    std::vector<Keyframe> prescribed_keyframes;
    // An external load (N per dof, 3 #V; empty: none) scaled at time t by
    // load_keyframes (empty: 1); added to the application's
    // Simulator::external_forces().
    std::vector<double> load;
    std::vector<Keyframe> load_keyframes;
    // Pressure and traction on surfaces, each with its own keyframes; added
    // to the external force like `load`.
    std::vector<SurfaceLoad> surface_loads;
    // The initial state (3 #V each; empty: at rest).
    std::vector<double> initial_displacement, initial_velocity;
    Integrator integrator = Integrator::SemiImplicit;
    IntegratorParameters integrator_parameters;
    double dt = 1e-3;                        // s
    int steps = 1000;
    SolverSettings solver;
    bool count_inverted_tets = true;         // per-step statistic (one pass over the tets)

    // Throws InvalidArgument naming the field (e.g. "dt", "fixed[3]"), and
    // MeshError for a mesh that check_mesh rejects (validate_mesh.hpp: an
    // index out of range, a non-finite coordinate, a degenerate, duplicate
    // or inverted tet). Every Simulator runs it.
    void validate() const;
};

const char* to_string(Integrator i);
// Every integrator with its name (scene JSON, CLI, Python), in enum order.
const std::vector<std::pair<const char*, Integrator>>& integrator_names();
const char* to_string(LinearSolver s);
const char* to_string(PreconditionerKind p);  // "block-jacobi", "amg"
// The kind named `name` ("block-jacobi" or "amg"); InvalidArgument naming
// `key` and the accepted names otherwise.
PreconditionerKind parse_preconditioner(const std::string& name, const std::string& key = "solver.preconditioner");

}  // namespace edgefem
