/**
 * @file edgefem.h
 * @brief The edgefem C API: a small, stable interface for game engines and
 * foreign-function interfaces.
 *
 * Two opaque handles: an ::edgefem_scene describes what is simulated (mesh,
 * material, fixed vertices, gravity, time step, integrator); an
 * ::edgefem_sim, created from a scene, owns the state and steps it. Every
 * function that can fail returns an ::edgefem_status; on failure,
 * edgefem_last_error() gives a message for the calling thread. No C++
 * exception ever crosses this interface.
 *
 * Vectors are xyz-interleaved doubles, 3 per vertex; vertex and tet indices
 * are 0-based int32. Buffer sizes are passed as counts of doubles (or
 * indices) and checked. Enumerations are passed as int32_t and
 * range-checked (EDGEFEM_ERROR_INVALID_ARGUMENT naming the argument).
 *
 * Handles: destroying NULL, or a handle already destroyed, does nothing.
 * Any other use of a destroyed handle cannot be detected and is undefined
 * behaviour (as after free()); set your pointer to NULL after destroying it.
 * (A handle destroyed twice with another created in between may have been
 * given the same address: the second destroy then frees the new one.)
 *
 * Threads: distinct handles may be used from distinct threads at once. One
 * simulation is used by one thread at a time: a step, static solve or
 * energies call while another thread is inside one of those on the same
 * simulation fails with EDGEFEM_ERROR_INVALID_ARGUMENT instead of racing
 * (other overlapping calls are not detected). edgefem_last_error() is per
 * thread.
 *
 * @code
 * edgefem_scene* scene = NULL;
 * edgefem_sim* sim = NULL;
 * if (edgefem_scene_create_from_arrays(X, nv, tets, nt, &scene) != EDGEFEM_OK ||
 *     edgefem_scene_set_gravity(scene, 0, 0, -9.81) != EDGEFEM_OK ||
 *     edgefem_sim_create(scene, &sim) != EDGEFEM_OK)
 *     fprintf(stderr, "%s\n", edgefem_last_error());
 * edgefem_sim_step(sim, NULL);
 * edgefem_sim_get_positions(sim, x, 3 * (size_t)nv);
 * edgefem_sim_destroy(sim);
 * edgefem_scene_destroy(scene);
 * @endcode
 */
#ifndef EDGEFEM_EDGEFEM_H
#define EDGEFEM_EDGEFEM_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(EDGEFEM_C_BUILDING)
#    define EDGEFEM_C_EXPORT __declspec(dllexport)
#  else
#    define EDGEFEM_C_EXPORT __declspec(dllimport)
#  endif
#else
#  define EDGEFEM_C_EXPORT __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Version of this interface; bumped only on incompatible changes. */
#define EDGEFEM_C_API_VERSION 1

/** Result of every fallible call. */
typedef enum edgefem_status {
    EDGEFEM_OK = 0,                    /**< success */
    EDGEFEM_ERROR_NULL_POINTER = 1,    /**< a required pointer argument was NULL */
    EDGEFEM_ERROR_INVALID_ARGUMENT = 2,/**< a value out of range, a size mismatch, an invalid scene */
    EDGEFEM_ERROR_MESH = 3,            /**< an unreadable or invalid mesh (NaN, index out of range, ...) */
    EDGEFEM_ERROR_FILE = 4,            /**< a scene file that cannot be read or parsed */
    EDGEFEM_ERROR_SIMULATION = 5,      /**< a step or solve failed (non-finite state, no convergence) */
    EDGEFEM_ERROR_OUT_OF_MEMORY = 6,   /**< an allocation failed */
    EDGEFEM_ERROR_INTERNAL = 7         /**< anything else (a bug: please report it) */
} edgefem_status;

/** Time integrators (see docs/scenes.md). */
typedef enum edgefem_integrator {
    EDGEFEM_EXPLICIT = 0,      /**< symplectic Euler */
    EDGEFEM_SEMI_IMPLICIT = 1, /**< linearised backward Euler, one CG solve per step */
    EDGEFEM_IMPLICIT = 2,      /**< backward Euler by Newton */
    EDGEFEM_NEWMARK = 3,                  /**< Newmark-beta (trapezoidal by default) by Newton */
    EDGEFEM_NEWMARK_LINEAR = 4,           /**< Newmark-beta, linearised (one K per step) */
    EDGEFEM_GENERALIZED_ALPHA = 5,        /**< generalized-alpha (rho_inf) by Newton */
    EDGEFEM_GENERALIZED_ALPHA_LINEAR = 6, /**< generalized-alpha, linearised */
    EDGEFEM_BDF2 = 7,                     /**< BDF2 by Newton */
    EDGEFEM_BDF2_LINEAR = 8,              /**< BDF2, linearised */
    EDGEFEM_VERLET = 9                    /**< velocity Verlet (explicit central differences) */
} edgefem_integrator;

/** Elastic models. */
typedef enum edgefem_model {
    EDGEFEM_MODEL_FE = 0, /**< StVK finite elements (edge-based form) */
    EDGEFEM_MODEL_SN = 1  /**< the nonlinear spring network (its special case) */
} edgefem_model;

/** Elastic methods (the same StVK element; docs/formulation.md). */
typedef enum edgefem_method {
    EDGEFEM_METHOD_EDGE = 0, /**< the edge-based kernels */
    EDGEFEM_METHOD_TET = 1   /**< the conventional per-tet kernels */
} edgefem_method;

/** Linear solvers of the implicit steps (docs/solvers.md). */
typedef enum edgefem_linear_solver {
    EDGEFEM_LINEAR_CG = 0,    /**< matrix-free CG with the scene's preconditioner */
    EDGEFEM_LINEAR_DIRECT = 1 /**< the assembled K factorised by CHOLMOD */
} edgefem_linear_solver;

/** What a step cost and did (a subset of the C++ StepStats). */
typedef struct edgefem_step_stats {
    double force_ms;          /**< internal forces */
    double stiffness_ms;      /**< building K */
    double solve_ms;          /**< linear solves */
    int32_t solver_iterations;/**< CG iterations */
    int32_t newton_iterations;/**< Newton iterations (implicit) */
    double residual;          /**< final relative residual of the last solve */
    int32_t inverted_tets;    /**< tets with non-positive volume at the end of the step */
} edgefem_step_stats;

/** Energies of the current state (J). */
typedef struct edgefem_energies {
    double kinetic;  /**< 1/2 v^T M v */
    double elastic;  /**< strain energy */
    double gravity;  /**< gravitational potential, -m g.x summed */
    double total;    /**< their sum */
} edgefem_energies;

/** A scene under construction (opaque). */
typedef struct edgefem_scene edgefem_scene;
/** A running simulation (opaque). */
typedef struct edgefem_sim edgefem_sim;
/** A render surface's points placed in a scene's tets (opaque). */
typedef struct edgefem_embedding edgefem_embedding;

/** The library version, e.g. "0.1.0" (static storage). */
EDGEFEM_C_EXPORT const char* edgefem_version_string(void);
/** The message of the last failed call on this thread ("" when none); valid
 *  until the next failing call on the same thread. */
EDGEFEM_C_EXPORT const char* edgefem_last_error(void);
/** A short name for a status code, e.g. "EDGEFEM_ERROR_MESH" (static storage). */
EDGEFEM_C_EXPORT const char* edgefem_status_string(edgefem_status status);
/** Keeps the memory this process frees for its own reuse (glibc: malloc's
 *  trim threshold at 512 MiB, its mmap threshold at 32 MiB) rather than
 *  handing it back to the system, where the AMG's refreshes would fault it
 *  in again (docs/parallel.md, "Set-up on a VM: page faults"). The peak
 *  memory does not change. Process-wide: call it from the program's main(),
 *  not from a library. Returns 1 where it changed malloc's settings, 0
 *  without glibc or where GLIBC_TUNABLES sets a glibc.malloc tunable. */
EDGEFEM_C_EXPORT int edgefem_retain_freed_memory(void);

/* ---- Scenes ------------------------------------------------------------ */

/** A scene from arrays: `positions` holds 3 `num_vertices` rest coordinates
 *  (metres), `tets` 4 `num_tets` 0-based vertex indices. The mesh is copied
 *  and validated (finite coordinates, indices in range, no degenerate,
 *  duplicate or inverted tets). Defaults: Y = 1e5 Pa, nu = 0.3,
 *  rho = 1000 kg/m^3, no gravity, semi-implicit, dt = 1e-3 s. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_create_from_arrays(const double* positions, int32_t num_vertices,
                                                                 const int32_t* tets, int32_t num_tets,
                                                                 edgefem_scene** out);
/** A scene on a mesh file (TetGen .node/.ele or prefix, Gmsh .msh, MEDIT
 *  .mesh, Vega .veg) or a "box:NXxNYxNZ" spec, with the defaults above. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_create_from_mesh_file(const char* path, edgefem_scene** out);
/** The same with the mesh options of a scene file's "mesh_options" (0 or 1
 *  each; anything else is EDGEFEM_ERROR_INVALID_ARGUMENT naming it):
 *  `fix_orientation` reorients inverted tets instead of refusing the mesh,
 *  `compact` removes vertices no tet uses (renumbering the rest, and the
 *  tagged triangles with them; the file's other vertex order is kept). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_create_from_mesh_file_with(const char* path, int32_t fix_orientation,
                                                                         int32_t compact, edgefem_scene** out);
/** A scene from a JSON scene file (docs/scenes.md): everything it sets. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_create_from_json(const char* path, edgefem_scene** out);
/** A scene on a generated box of nx x ny x nz cubes of side `cell`, centred at
 *  the origin; vertex (i, j, k) has index i + (nx+1) (j + (ny+1) k). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_create_box(int32_t nx, int32_t ny, int32_t nz, double cell,
                                                         edgefem_scene** out);
/** Frees a scene (NULL, or a scene already destroyed, is ignored).
 *  Simulations created from it stay valid. */
EDGEFEM_C_EXPORT void edgefem_scene_destroy(edgefem_scene* scene);

/** Number of vertices and tets. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_counts(const edgefem_scene* scene, int32_t* num_vertices,
                                                     int32_t* num_tets);
/** Copies the rest positions (count = 3 x num_vertices). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_get_rest_positions(const edgefem_scene* scene, double* out,
                                                                 size_t count);
/** Copies the tets: 4 vertex indices per tet (count = 4 x num_tets), as
 *  validated (every tet positively oriented). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_get_tets(const edgefem_scene* scene, int32_t* out, size_t count);
/** The mesh's boundary for rendering: the faces of exactly one tet, wound so
 *  that (b - a) x (c - a) points out of the body. Its triangle count, then
 *  the triangles (3 vertex indices each; count = 3 x num_triangles). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_boundary_count(const edgefem_scene* scene, size_t* num_triangles);
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_get_boundary(const edgefem_scene* scene, int32_t* out, size_t count);
/** One material for the whole mesh: Young's modulus (Pa), Poisson ratio in
 *  (-1, 0.5), density (kg/m^3). Replaces every region's material too. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_material(edgefem_scene* scene, double young, double poisson,
                                                           double density);

/* ---- Regions: per-tet ids and per-region materials -------------------- */

/** Copies each tet's region id (count = num_tets): the mesh file's tet
 *  attribute (TetGen), physical tag (Gmsh), reference (MEDIT) or material
 *  index (Vega); 0 where the mesh has none. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_get_regions(const edgefem_scene* scene, int32_t* out, size_t count);
/** Replaces the tets' region ids (count = num_tets; count 0: every tet in region 0). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_regions(edgefem_scene* scene, const int32_t* regions,
                                                          size_t count);
/** The material of the tets of region `region` (the others keep theirs, or
 *  the scene's material). The values are checked as edgefem_scene_set_material's. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_region_material(edgefem_scene* scene, int32_t region, double young,
                                                                  double poisson, double density);

/* ---- Tagged surfaces (docs/scenes.md, "Surface selections") ------------ */

/** The mesh file's tagged boundary triangles with tag `tag` (Gmsh physical
 *  surface, or its surface entity when it has none; TetGen .face boundary
 *  marker; MEDIT Triangles reference): their count, then the triangles (3
 *  vertex indices each, count = 3 x num_triangles, in the file's winding). A
 *  tag no triangle has is EDGEFEM_ERROR_INVALID_ARGUMENT naming it and the
 *  tags there are. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_surface_count(const edgefem_scene* scene, int32_t tag,
                                                            size_t* num_triangles);
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_get_surface(const edgefem_scene* scene, int32_t tag, int32_t* out,
                                                          size_t count);
/** The tag of a Gmsh physical surface's name ($PhysicalNames); a name no
 *  surface has, or one that names several tags, is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT naming it. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_surface_tag(const edgefem_scene* scene, const char* name, int32_t* tag);
/** Adds the vertices of the triangles tagged `tag` to the fixed vertices. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_fix_surface(edgefem_scene* scene, int32_t tag);

/* ---- Surface loads (docs/scenes.md, "Surface loads") -------------------- */

/** Adds a pressure (Pa; positive pushes into the body, along the inward
 *  normal) and a traction (tx, ty, tz: Pa, force per area, a fixed vector)
 *  on the boundary triangles tagged `tag`, scaled by keyframes (times,
 *  values, key_count; 0 keys: constant). Dead loads on the rest surface:
 *  each triangle's force (t - p n) A goes to its vertices in thirds. A tag
 *  no triangle has, or a tagged triangle that is not on the boundary, is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT naming it. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_add_surface_load(edgefem_scene* scene, int32_t tag, double pressure,
                                                               double tx, double ty, double tz, const double* times,
                                                               const double* values, size_t key_count);
/** The same on triangles given as 3 vertex indices each (count = 3 x
 *  triangles), wound so that (b - a) x (c - a) points out of the body, as
 *  edgefem_scene_get_boundary gives them (all of them: the whole boundary). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_add_surface_load_triangles(edgefem_scene* scene,
                                                                         const int32_t* triangles, size_t count,
                                                                         double pressure, double tx, double ty,
                                                                         double tz, const double* times,
                                                                         const double* values, size_t key_count);
/** Removes every surface load. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_clear_surface_loads(edgefem_scene* scene);
/** Replaces the fixed vertices (held at rest); count 0 frees all. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_fixed(edgefem_scene* scene, const int32_t* vertices,
                                                        size_t count);
/** Replaces the prescribed vertices: vertices[i] is driven to the position
 *  targets[3 i .. 3 i + 2] (m), moved linearly from rest over `steps` (>= 1)
 *  time steps and held there; a static solve reaches the targets fully.
 *  count 0 clears them. A vertex out of range, prescribed twice or also
 *  fixed, or a non-finite target, is EDGEFEM_ERROR_INVALID_ARGUMENT and
 *  leaves the scene unchanged. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_prescribed(edgefem_scene* scene, const int32_t* vertices,
                                                             const double* targets, size_t count, int32_t steps);
/** Gravity (m/s^2). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_gravity(edgefem_scene* scene, double gx, double gy, double gz);
/** Time step (s, finite and > 0). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_dt(edgefem_scene* scene, double dt);
/** Integrator: an ::edgefem_integrator value; any other integer is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_integrator(edgefem_scene* scene, int32_t integrator);
/** Newmark's beta in (0, 1/2] and gamma in [1/2, 1] (defaults 1/4, 1/2). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_newmark(edgefem_scene* scene, double beta, double gamma);
/** Generalized-alpha's spectral radius at infinite frequency rho_inf in [0, 1] (default 0.8). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_generalized_alpha(edgefem_scene* scene, double rho_inf);
/** Initial displacement and velocity, 3 x (vertex count) values each (NULL: zero);
 *  `count` must be 3 x (vertex count). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_initial_state(edgefem_scene* scene, const double* displacement,
                                                                const double* velocity, size_t count);
/** Prescribed motion as keyframes: at times[k] (s, increasing) the fraction
 *  values[k] of the targets is reached, linear in between (count 0: the
 *  linear ramp again). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_prescribed_keyframes(edgefem_scene* scene, const double* times,
                                                                       const double* values, size_t count);
/** An external load (N per dof, 3 x (vertex count) values; count 0: none), scaled by
 *  keyframes (times, values, key_count; 0 keys: constant). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_load(edgefem_scene* scene, const double* load, size_t count,
                                                       const double* times, const double* values, size_t key_count);
/** Elastic model: an ::edgefem_model value (FE or SN); any other integer is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_model(edgefem_scene* scene, int32_t model);
/** Rayleigh damping D = alpha M + beta K. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_damping(edgefem_scene* scene, double alpha, double beta);
/** Elastic method: an ::edgefem_method value; any other integer is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_method(edgefem_scene* scene, int32_t method);
/** Linear solver of the implicit steps and static solves: an
 *  ::edgefem_linear_solver value; any other integer is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT. */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_linear_solver(edgefem_scene* scene, int32_t solver);
/** Newton's settings (the Newton integrators and static solves): relative
 *  tolerance (> 0), iteration cap (>= 1) and the static solve's initial
 *  number of load steps (>= 1). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_newton(edgefem_scene* scene, double tolerance,
                                                         int32_t max_iterations, int32_t load_steps);
/** CG settings: relative tolerance, iteration cap, and a fixed budget
 *  (`fixed_iterations` > 0: exactly that many warm-started iterations per
 *  solve, the real-time setting; 0: iterate to the tolerance). */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_cg(edgefem_scene* scene, double tolerance,
                                                     int32_t max_iterations, int32_t fixed_iterations);
/** CG's preconditioner by name: "block-jacobi" or "amg" (docs/solvers.md);
 *  another name is EDGEFEM_ERROR_INVALID_ARGUMENT naming
 *  "solver.preconditioner". */
EDGEFEM_C_EXPORT edgefem_status edgefem_scene_set_preconditioner(edgefem_scene* scene, const char* name);

/* ---- Simulations ------------------------------------------------------- */

/** How and where a simulation runs: the same options, with the same
 *  defaults, as the edgefem program's and the Python module's. A NULL string
 *  takes the default. */
typedef struct edgefem_run_options {
    /** "auto" (every core: the CPU back-end on its thread pool, adaptive),
     *  "serial", "omp", "tbb", "pool" or "reference" (plain loops; slow). */
    const char* backend;
    /** Threads of auto/omp/tbb/pool; 0: every hardware thread. */
    int32_t threads;
    /** "auto", "colour", "gather", "atomic", "private" or "owner". */
    const char* variant;
    /** "dynamic" or "static" (never changes a result). */
    const char* schedule;
    /** 1: loops run serially where that measured faster (same results); 0: on the threads. */
    int32_t adaptive;
    /** The internal vertex numbering: "rcm", "input", "random", "morton", "nd" or "metis"
     *  (every array in and out stays in the scene's numbering). */
    const char* ordering;
    /** "tet-local" or "tsep-list". */
    const char* layout;
} edgefem_run_options;

/** The defaults (backend "auto", every thread, adaptive, "rcm"). */
EDGEFEM_C_EXPORT void edgefem_run_options_default(edgefem_run_options* out);

/** Validates the scene and builds a simulation at rest (u = 0, v = 0) with
 *  the default run options. The scene is copied: later changes to it do not
 *  affect the simulation. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_create(const edgefem_scene* scene, edgefem_sim** out);
/** The same with run options (NULL: the defaults); an unknown value is
 *  EDGEFEM_ERROR_INVALID_ARGUMENT with a message naming it. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_create_with(const edgefem_scene* scene, const edgefem_run_options* run,
                                                        edgefem_sim** out);
/** Frees a simulation (NULL, or a simulation already destroyed, is ignored). */
EDGEFEM_C_EXPORT void edgefem_sim_destroy(edgefem_sim* sim);

/** Number of vertices. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_num_vertices(const edgefem_sim* sim, int32_t* out);
/** Advances by dt; `stats` may be NULL. On EDGEFEM_ERROR_SIMULATION the
 *  message names the step and vertex. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_step(edgefem_sim* sim, edgefem_step_stats* stats);
/** Static equilibrium under the current loads; the result becomes the state.
 *  `converged` may be NULL. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_solve_static(edgefem_sim* sim, int32_t* converged);

/** Replaces all external forces (N, count = 3 x num_vertices); they stay until changed. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_set_external_forces(edgefem_sim* sim, const double* forces,
                                                                size_t count);
/** Sets the external force on one vertex. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_set_external_force(edgefem_sim* sim, int32_t vertex, double fx,
                                                               double fy, double fz);
/** Zeroes all external forces. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_clear_external_forces(edgefem_sim* sim);

/** Current positions X + u (count = 3 x num_vertices). */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_get_positions(const edgefem_sim* sim, double* out, size_t count);
/** Displacement u = x - X (count = 3 x num_vertices). */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_get_displacement(const edgefem_sim* sim, double* out, size_t count);
/** Velocity (count = 3 x num_vertices). */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_get_velocity(const edgefem_sim* sim, double* out, size_t count);
/** Sets the displacement (count = 3 num_vertices, finite). */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_set_displacement(edgefem_sim* sim, const double* u, size_t count);
/** Sets the velocity (count = 3 num_vertices, finite). */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_set_velocity(edgefem_sim* sim, const double* v, size_t count);
/** Energies of the current state. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_energies(edgefem_sim* sim, edgefem_energies* out);
/** Simulated time (s) and number of steps taken; either may be NULL. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_time(const edgefem_sim* sim, double* time, int64_t* steps);

/** Writes a checkpoint: the simulation's whole state (displacement,
 *  velocity, external forces, time, step count, the integrator's history and
 *  the solver set-ups that outlive a step) to `path`, whole or not at all
 *  (docs/api.md, "Checkpoints"). EDGEFEM_ERROR_FILE naming the file when it
 *  cannot be written. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_save_checkpoint(edgefem_sim* sim, const char* path);
/** Reads a checkpoint into a simulation of the same scene (mesh, integrator,
 *  linear solver and preconditioner) and ordering: stepping on continues bit
 *  for bit as if the run had not stopped (same run options). A file that
 *  cannot be read, is not a checkpoint, is truncated or corrupt, or was
 *  written for another mesh, integrator, solver, ordering or precision is
 *  EDGEFEM_ERROR_FILE with a message naming the file and the difference; the
 *  state is then unchanged. */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_load_checkpoint(edgefem_sim* sim, const char* path);

/* ---- Render surfaces (docs/api.md, "Surfaces for rendering") ------------ */

/** Places the points of a separate render surface (count = 3 x points,
 *  finite) in the scene's tets: each point then moves with its tet (a point
 *  outside the mesh with its nearest tet, affinely). The embedding keeps a
 *  copy of the mesh, so the scene may be destroyed first. */
EDGEFEM_C_EXPORT edgefem_status edgefem_embedding_create(const edgefem_scene* scene, const double* points, size_t count,
                                                         edgefem_embedding** out);
/** Frees an embedding (NULL, or one already destroyed, is ignored). */
EDGEFEM_C_EXPORT void edgefem_embedding_destroy(edgefem_embedding* embedding);
/** The number of points it places. */
EDGEFEM_C_EXPORT edgefem_status edgefem_embedding_num_points(const edgefem_embedding* embedding, size_t* num_points);
/** How far outside the mesh each point lies (count = points; 0 inside its
 *  tet, else an estimate in metres). */
EDGEFEM_C_EXPORT edgefem_status edgefem_embedding_get_outside(const edgefem_embedding* embedding, double* out,
                                                              size_t count);
/** The embedded points at the simulation's current displacement
 *  (count = 3 x points). The simulation must run on the mesh the embedding
 *  was made for (same vertex count). */
EDGEFEM_C_EXPORT edgefem_status edgefem_sim_embedded_positions(const edgefem_sim* sim,
                                                               const edgefem_embedding* embedding, double* out,
                                                               size_t count);
/** Area-weighted unit vertex normals of a triangle mesh: triangles
 *  (3 x num_triangles vertex indices, each in [0, num_vertices)), positions
 *  and normals (3 x num_vertices each); 0 for a vertex no triangle uses. */
EDGEFEM_C_EXPORT edgefem_status edgefem_vertex_normals(const int32_t* triangles, size_t num_triangles,
                                                       const double* positions, size_t num_vertices, double* normals);

#ifdef __cplusplus
}
#endif

#endif /* EDGEFEM_EDGEFEM_H */
