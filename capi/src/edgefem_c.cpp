// The C API (capi/include/edgefem/edgefem.h) over the C++ core. Every entry
// point runs its body inside guard(), which turns any exception into a
// status code and a thread-local message: nothing throws across the C
// boundary.
#include "edgefem/edgefem.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <span>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/retain_freed_memory.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/surface_selection.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "edgefem/parallel/run_options.hpp"

#ifndef EDGEFEM_VERSION
#define EDGEFEM_VERSION "unknown"
#endif

struct edgefem_scene {
    edgefem::Scene scene;
};

struct edgefem_embedding {
    edgefem::Mesh mesh;  // the scene's, copied: the scene may go first
    edgefem::Embedding embedding;
};

struct edgefem_sim {
    explicit edgefem_sim(std::unique_ptr<edgefem::OrderedSimulator<double>> s) : owner(std::move(s)), sim(*owner) {}
    std::unique_ptr<edgefem::OrderedSimulator<double>> owner;
    edgefem::OrderedSimulator<double>& sim;
};

namespace {

thread_local std::string g_last_error;

// An error raised by the C layer itself, with its status.
struct CError {
    edgefem_status status;
    std::string message;
};

edgefem_status fail(edgefem_status status, std::string message) {
    try {
        g_last_error = std::move(message);
    } catch (...) {
        g_last_error.clear();
    }
    return status;
}

// Runs body (returning void); maps every exception to a status. A bare
// InvalidArgument becomes `invalid_status` (EDGEFEM_ERROR_FILE for scene files).
template <class Body>
edgefem_status guard(const char* fn, Body&& body, edgefem_status invalid_status = EDGEFEM_ERROR_INVALID_ARGUMENT) {
    const std::string prefix = std::string(fn) + ": ";
    try {
        body();
        return EDGEFEM_OK;
    } catch (const CError& e) {
        return fail(e.status, prefix + e.message);
    } catch (const edgefem::SimulationError& e) {
        return fail(EDGEFEM_ERROR_SIMULATION, prefix + e.what());
    } catch (const edgefem::MeshError& e) {
        return fail(EDGEFEM_ERROR_MESH, prefix + e.what());
    } catch (const edgefem::InvalidArgument& e) {
        return fail(invalid_status, prefix + e.what());
    } catch (const edgefem::Error& e) {
        return fail(invalid_status == EDGEFEM_ERROR_FILE ? EDGEFEM_ERROR_FILE : EDGEFEM_ERROR_INTERNAL,
                    prefix + e.what());
    } catch (const std::bad_alloc&) {
        return fail(EDGEFEM_ERROR_OUT_OF_MEMORY, prefix + "out of memory");
    } catch (const std::exception& e) {
        return fail(EDGEFEM_ERROR_INTERNAL, prefix + e.what());
    } catch (...) {
        return fail(EDGEFEM_ERROR_INTERNAL, prefix + "unknown exception");
    }
}

void require(const void* p, const char* name) {
    if (!p) throw CError{EDGEFEM_ERROR_NULL_POINTER, std::string(name) + " is NULL"};
}

// A checkpoint call: the file's problems (IoError writing, CheckpointError
// reading) are EDGEFEM_ERROR_FILE.
template <class Call>
edgefem_status checkpoint_call(const char* fn, edgefem_sim* sim, const char* path, Call&& call) {
    return guard(fn, [&] {
        require(sim, "sim");
        require(path, "path");
        try {
            call(sim->sim, path);
        } catch (const edgefem::IoError& e) {
            throw CError{EDGEFEM_ERROR_FILE, e.what()};
        } catch (const edgefem::CheckpointError& e) {
            throw CError{EDGEFEM_ERROR_FILE, e.what()};
        }
    });
}

[[noreturn]] void invalid(std::string message) { throw CError{EDGEFEM_ERROR_INVALID_ARGUMENT, std::move(message)}; }

// `name` holds `count` values where `expected` (`what`, in words) are needed.
void require_count(size_t count, size_t expected, const char* name, const std::string& what = "3 x #V") {
    if (count != expected)
        invalid(std::string(name) + ": count is " + std::to_string(count) + ", expected " + what + " = " +
                std::to_string(expected));
}

// `per_vertex`: a is xyz per vertex, and the message names the vertex too
// (for one vector, such as gravity, a vertex would mean nothing).
void require_finite(const double* a, size_t n, const char* name, bool per_vertex = true) {
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(a[i]))
            invalid(std::string(name) + "[" + std::to_string(i) + "] is not finite" +
                    (per_vertex ? " (vertex " + std::to_string(i / 3) + ")" : std::string()));
}

// The handles create functions returned and no destroy has freed yet, so
// that destroying one twice (or a pointer never returned) is a no-op. Left
// alive at exit: a destroy from another static destructor stays safe.
template <class Handle>
struct LiveHandles {
    std::mutex mutex;
    std::unordered_set<const Handle*> live;

    static LiveHandles& get() {
        static auto* registry = new LiveHandles;
        return *registry;
    }
    // Registers `h` (owned until then) and hands it to the caller.
    static Handle* track(std::unique_ptr<Handle> h) {
        LiveHandles& r = get();
        const std::lock_guard lock(r.mutex);
        r.live.insert(h.get());
        return h.release();
    }
    // Whether `h` was live (it no longer is).
    static bool forget(const Handle* h) {
        LiveHandles& r = get();
        const std::lock_guard lock(r.mutex);
        return r.live.erase(h) == 1;
    }
};

template <class Handle, class... Args>
Handle* new_handle(Args&&... args) {
    return LiveHandles<Handle>::track(std::make_unique<Handle>(std::forward<Args>(args)...));
}

template <class Handle>
void destroy_handle(Handle* h) {
    if (h && LiveHandles<Handle>::forget(h)) delete h;
}

edgefem::Scene default_scene_for(edgefem::Mesh mesh) {
    edgefem::Scene s;
    s.mesh = std::move(mesh);
    s.materials = edgefem::Material{};
    return s;
}

// The mesh options of edgefem_scene_create_from_mesh_file_with (0 or 1 each).
struct MeshFlags {
    int32_t fix_orientation = 0, compact = 0;
    bool offered = false;  // whether the caller could have set them
};

edgefem_status make_scene(const char* fn, edgefem_scene** out, edgefem::Mesh (*build)(const void*),
                          const void* ctx, MeshFlags flags = {}) {
    if (out) *out = nullptr;
    return guard(fn, [&] {
        require(out, "out");
        if (flags.fix_orientation != 0 && flags.fix_orientation != 1)
            invalid("fix_orientation: " + std::to_string(flags.fix_orientation) + " (expected 0 or 1)");
        if (flags.compact != 0 && flags.compact != 1)
            invalid("compact: " + std::to_string(flags.compact) + " (expected 0 or 1)");
        edgefem::Mesh mesh = build(ctx);
        edgefem::ValidationOptions options;
        options.fix_orientation = flags.fix_orientation == 1;
        options.compact_unreferenced = flags.compact == 1;
        // Messages name only the options the caller has.
        options.fix_orientation_hint = flags.offered ? "pass fix_orientation = 1 (edgefem_scene_create_from_mesh_file_with)"
                                                     : "reorder their vertices before passing the mesh (or use edgefem_scene_create_from_mesh_file_with)";
        options.compact_hint = flags.offered ? "pass compact = 1 (edgefem_scene_create_from_mesh_file_with)"
                                             : "leave them out (or use edgefem_scene_create_from_mesh_file_with with compact = 1)";
        edgefem::validate_mesh(mesh, options);
        *out = new_handle<edgefem_scene>(edgefem_scene{default_scene_for(std::move(mesh))});
    });
}

// A mesh file or "box:NXxNYxNZ" spec.
edgefem::Mesh mesh_from_path(const void* p) {
    const char* path = static_cast<const char*>(p);
    require(path, "path");
    const std::string s(path);
    return edgefem::is_box_spec(s) ? edgefem::make_box_from_spec(s) : edgefem::read_mesh(s);
}

std::size_t dofs(const edgefem_sim* sim) { return 3 * std::size_t(sim->sim.num_vertices()); }

}  // namespace

extern "C" {

const char* edgefem_version_string(void) { return EDGEFEM_VERSION; }

int edgefem_retain_freed_memory(void) { return edgefem::retain_freed_memory() ? 1 : 0; }

const char* edgefem_last_error(void) { return g_last_error.c_str(); }

const char* edgefem_status_string(edgefem_status status) {
    switch (status) {
        case EDGEFEM_OK: return "EDGEFEM_OK";
        case EDGEFEM_ERROR_NULL_POINTER: return "EDGEFEM_ERROR_NULL_POINTER";
        case EDGEFEM_ERROR_INVALID_ARGUMENT: return "EDGEFEM_ERROR_INVALID_ARGUMENT";
        case EDGEFEM_ERROR_MESH: return "EDGEFEM_ERROR_MESH";
        case EDGEFEM_ERROR_FILE: return "EDGEFEM_ERROR_FILE";
        case EDGEFEM_ERROR_SIMULATION: return "EDGEFEM_ERROR_SIMULATION";
        case EDGEFEM_ERROR_OUT_OF_MEMORY: return "EDGEFEM_ERROR_OUT_OF_MEMORY";
        case EDGEFEM_ERROR_INTERNAL: return "EDGEFEM_ERROR_INTERNAL";
    }
    return "EDGEFEM_ERROR_UNKNOWN";
}

// ---- Scenes ----

edgefem_status edgefem_scene_create_from_arrays(const double* positions, int32_t num_vertices, const int32_t* tets,
                                                int32_t num_tets, edgefem_scene** out) {
    struct Args {
        const double* X;
        int32_t nv;
        const int32_t* T;
        int32_t nt;
    } args{positions, num_vertices, tets, num_tets};
    return make_scene("edgefem_scene_create_from_arrays", out, [](const void* p) {
        const Args& a = *static_cast<const Args*>(p);
        require(a.X, "positions");
        require(a.T, "tets");
        if (a.nv <= 0) invalid("num_vertices must be positive, got " + std::to_string(a.nv));
        if (a.nt <= 0) invalid("num_tets must be positive, got " + std::to_string(a.nt));
        edgefem::Mesh m;
        m.X.assign(a.X, a.X + 3 * std::size_t(a.nv));
        m.tets.assign(a.T, a.T + 4 * std::size_t(a.nt));
        return m;
    }, &args);
}

edgefem_status edgefem_scene_create_from_mesh_file(const char* path, edgefem_scene** out) {
    return make_scene("edgefem_scene_create_from_mesh_file", out, mesh_from_path, path);
}

edgefem_status edgefem_scene_create_from_mesh_file_with(const char* path, int32_t fix_orientation, int32_t compact,
                                                       edgefem_scene** out) {
    return make_scene("edgefem_scene_create_from_mesh_file_with", out, mesh_from_path, path,
                      MeshFlags{fix_orientation, compact, true});
}

edgefem_status edgefem_scene_create_box(int32_t nx, int32_t ny, int32_t nz, double cell, edgefem_scene** out) {
    struct Args {
        int32_t nx, ny, nz;
        double cell;
    } args{nx, ny, nz, cell};
    return make_scene("edgefem_scene_create_box", out, [](const void* p) {
        const Args& a = *static_cast<const Args*>(p);
        if (!(std::isfinite(a.cell) && a.cell > 0)) invalid("cell must be finite and positive");
        return edgefem::make_box(a.nx, a.ny, a.nz, a.cell);
    }, &args);
}

edgefem_status edgefem_scene_create_from_json(const char* path, edgefem_scene** out) {
    if (out) *out = nullptr;
    return guard("edgefem_scene_create_from_json", [&] {
        require(out, "out");
        require(path, "path");
        edgefem::SceneFile file = edgefem::load_scene(path);
        *out = new_handle<edgefem_scene>(edgefem_scene{std::move(file.scene)});
    }, EDGEFEM_ERROR_FILE);
}

void edgefem_scene_destroy(edgefem_scene* scene) { destroy_handle(scene); }

edgefem_status edgefem_scene_counts(const edgefem_scene* scene, int32_t* num_vertices, int32_t* num_tets) {
    return guard("edgefem_scene_counts", [&] {
        require(scene, "scene");
        if (num_vertices) *num_vertices = scene->scene.mesh.num_vertices();
        if (num_tets) *num_tets = scene->scene.mesh.num_tets();
    });
}

edgefem_status edgefem_scene_get_rest_positions(const edgefem_scene* scene, double* out, size_t count) {
    return guard("edgefem_scene_get_rest_positions", [&] {
        require(scene, "scene");
        require(out, "out");
        const auto& X = scene->scene.mesh.X;
        require_count(count, X.size(), "out");
        std::copy(X.begin(), X.end(), out);
    });
}

edgefem_status edgefem_scene_get_tets(const edgefem_scene* scene, int32_t* out, size_t count) {
    return guard("edgefem_scene_get_tets", [&] {
        require(scene, "scene");
        require(out, "out");
        const auto& T = scene->scene.mesh.tets;
        require_count(count, T.size(), "out", "4 x #T");
        std::copy(T.begin(), T.end(), out);
    });
}

edgefem_status edgefem_scene_boundary_count(const edgefem_scene* scene, size_t* num_triangles) {
    return guard("edgefem_scene_boundary_count", [&] {
        require(scene, "scene");
        require(num_triangles, "num_triangles");
        *num_triangles = edgefem::boundary_surface(scene->scene.mesh).triangles.size();
    });
}

edgefem_status edgefem_scene_get_boundary(const edgefem_scene* scene, int32_t* out, size_t count) {
    return guard("edgefem_scene_get_boundary", [&] {
        require(scene, "scene");
        require(out, "out");
        const auto tri = edgefem::boundary_surface(scene->scene.mesh).triangles;
        require_count(count, 3 * tri.size(), "out", "3 x (boundary triangles)");
        for (std::size_t k = 0; k < tri.size(); ++k)
            for (int i = 0; i < 3; ++i) out[3 * k + i] = tri[k][i];
    });
}

edgefem_status edgefem_scene_set_material(edgefem_scene* scene, double young, double poisson, double density) {
    return guard("edgefem_scene_set_material", [&] {
        require(scene, "scene");
        const edgefem::Material m{young, poisson, density};
        m.validate();
        scene->scene.materials = edgefem::Materials(m);
    });
}

edgefem_status edgefem_scene_set_fixed(edgefem_scene* scene, const int32_t* vertices, size_t count) {
    return guard("edgefem_scene_set_fixed", [&] {
        require(scene, "scene");
        if (count > 0) require(vertices, "vertices");
        const int32_t nv = scene->scene.mesh.num_vertices();
        for (size_t i = 0; i < count; ++i)
            if (vertices[i] < 0 || vertices[i] >= nv)
                invalid("vertices[" + std::to_string(i) + "] = " + std::to_string(vertices[i]) +
                        " is out of range [0, " + std::to_string(nv) + ")");
        scene->scene.fixed.assign(vertices, vertices + count);
    });
}

edgefem_status edgefem_scene_set_prescribed(edgefem_scene* scene, const int32_t* vertices, const double* targets,
                                            size_t count, int32_t steps) {
    return guard("edgefem_scene_set_prescribed", [&] {
        require(scene, "scene");
        if (count > 0) {
            require(vertices, "vertices");
            require(targets, "targets");
        }
        if (steps < 1) invalid("steps must be >= 1, got " + std::to_string(steps));
        require_finite(targets, 3 * count, "targets");
        edgefem::Scene s = scene->scene;  // checked whole before it replaces the scene's
        s.prescribed.clear();
        for (size_t i = 0; i < count; ++i)
            s.prescribed.push_back({vertices[i], {targets[3 * i], targets[3 * i + 1], targets[3 * i + 2]}});
        s.prescribed_steps = steps;
        s.validate();  // vertices in range, not fixed, not twice: messages name prescribed[i]
        scene->scene.prescribed = std::move(s.prescribed);
        scene->scene.prescribed_steps = steps;
    });
}

edgefem_status edgefem_scene_set_gravity(edgefem_scene* scene, double gx, double gy, double gz) {
    return guard("edgefem_scene_set_gravity", [&] {
        require(scene, "scene");
        const double g[3] = {gx, gy, gz};
        require_finite(g, 3, "gravity", false);
        scene->scene.gravity = {gx, gy, gz};
    });
}

edgefem_status edgefem_scene_set_dt(edgefem_scene* scene, double dt) {
    return guard("edgefem_scene_set_dt", [&] {
        require(scene, "scene");
        if (!(std::isfinite(dt) && dt > 0)) invalid("dt must be finite and positive, got " + std::to_string(dt));
        scene->scene.dt = dt;
    });
}

edgefem_status edgefem_scene_set_integrator(edgefem_scene* scene, int32_t integrator) {
    return guard("edgefem_scene_set_integrator", [&] {
        require(scene, "scene");
        // The C values are the enum's order (integrator_names()).
        static_assert(int(edgefem::Integrator::Implicit) == EDGEFEM_IMPLICIT &&
                      int(edgefem::Integrator::Verlet) == EDGEFEM_VERLET);
        const auto& names = edgefem::integrator_names();
        if (int(integrator) < 0 || std::size_t(integrator) >= names.size())
            invalid("integrator: " + std::to_string(integrator) + " is not an edgefem_integrator (0 to " +
                    std::to_string(names.size() - 1) + ")");
        scene->scene.integrator = names[std::size_t(integrator)].second;
    });
}

namespace {
// `count` values for a per-dof vector of the scene's mesh.
void require_per_dof(const edgefem_scene* scene, size_t count, const char* name) {
    const size_t nd = 3 * size_t(scene->scene.mesh.num_vertices());
    if (count != nd) invalid(std::string(name) + ": expected 3 x #V = " + std::to_string(nd) + " values, got " + std::to_string(count));
}
std::vector<edgefem::Keyframe> keyframes(const double* times, const double* values, size_t count, const char* name) {
    if (count > 0) {
        require(times, "times");
        require(values, "values");
    }
    std::vector<edgefem::Keyframe> k;
    for (size_t i = 0; i < count; ++i) {
        if (!std::isfinite(times[i]) || !std::isfinite(values[i]))
            invalid(std::string(name) + "[" + std::to_string(i) + "] is not finite");
        if (i > 0 && !(times[i] > times[i - 1]))
            invalid(std::string(name) + "[" + std::to_string(i) + "]: times must increase strictly");
        k.push_back({times[i], values[i]});
    }
    return k;
}
}  // namespace

edgefem_status edgefem_scene_set_initial_state(edgefem_scene* scene, const double* displacement, const double* velocity,
                                               size_t count) {
    return guard("edgefem_scene_set_initial_state", [&] {
        require(scene, "scene");
        require_per_dof(scene, count, "count");
        if (displacement) require_finite(displacement, count, "displacement");
        if (velocity) require_finite(velocity, count, "velocity");
        scene->scene.initial_displacement.assign(displacement, displacement ? displacement + count : displacement);
        scene->scene.initial_velocity.assign(velocity, velocity ? velocity + count : velocity);
    });
}

edgefem_status edgefem_scene_set_prescribed_keyframes(edgefem_scene* scene, const double* times, const double* values,
                                                      size_t count) {
    return guard("edgefem_scene_set_prescribed_keyframes", [&] {
        require(scene, "scene");
        scene->scene.prescribed_keyframes = keyframes(times, values, count, "prescribed.keyframes");
    });
}

edgefem_status edgefem_scene_set_load(edgefem_scene* scene, const double* load, size_t count, const double* times,
                                      const double* values, size_t key_count) {
    return guard("edgefem_scene_set_load", [&] {
        require(scene, "scene");
        if (count > 0) {
            require(load, "load");
            require_per_dof(scene, count, "count");
            require_finite(load, count, "load");
        }
        std::vector<edgefem::Keyframe> k = keyframes(times, values, key_count, "load.keyframes");
        if (count == 0 && !k.empty()) invalid("load.keyframes: keyframes without a load");
        scene->scene.load.assign(load, load ? load + count : load);
        scene->scene.load_keyframes = std::move(k);
    });
}

edgefem_status edgefem_scene_set_newmark(edgefem_scene* scene, double beta, double gamma) {
    return guard("edgefem_scene_set_newmark", [&] {
        require(scene, "scene");
        if (!(beta > 0 && beta <= 0.5)) invalid("newmark.beta must lie in (0, 1/2], got " + std::to_string(beta));
        if (!(gamma >= 0.5 && gamma <= 1)) invalid("newmark.gamma must lie in [1/2, 1], got " + std::to_string(gamma));
        scene->scene.integrator_parameters.newmark_beta = beta;
        scene->scene.integrator_parameters.newmark_gamma = gamma;
    });
}

edgefem_status edgefem_scene_set_generalized_alpha(edgefem_scene* scene, double rho_inf) {
    return guard("edgefem_scene_set_generalized_alpha", [&] {
        require(scene, "scene");
        if (!(rho_inf >= 0 && rho_inf <= 1))
            invalid("generalized_alpha.rho_inf must lie in [0, 1], got " + std::to_string(rho_inf));
        scene->scene.integrator_parameters.rho_inf = rho_inf;
    });
}

edgefem_status edgefem_scene_set_model(edgefem_scene* scene, int32_t model) {
    return guard("edgefem_scene_set_model", [&] {
        require(scene, "scene");
        switch (model) {
            case EDGEFEM_MODEL_FE: scene->scene.model = edgefem::ModelKind::FE; break;
            case EDGEFEM_MODEL_SN: scene->scene.model = edgefem::ModelKind::SN; break;
            default:
                invalid("model: " + std::to_string(model) +
                        " is not an edgefem_model (EDGEFEM_MODEL_FE 0, EDGEFEM_MODEL_SN 1)");
        }
    });
}

edgefem_status edgefem_scene_set_damping(edgefem_scene* scene, double alpha, double beta) {
    return guard("edgefem_scene_set_damping", [&] {
        require(scene, "scene");
        if (!(std::isfinite(alpha) && alpha >= 0 && std::isfinite(beta) && beta >= 0))
            invalid("damping coefficients must be finite and non-negative");
        scene->scene.rayleigh_alpha = alpha;
        scene->scene.rayleigh_beta = beta;
    });
}

edgefem_status edgefem_scene_set_cg(edgefem_scene* scene, double tolerance, int32_t max_iterations,
                                    int32_t fixed_iterations) {
    return guard("edgefem_scene_set_cg", [&] {
        require(scene, "scene");
        if (!(std::isfinite(tolerance) && tolerance > 0)) invalid("tolerance must be finite and positive");
        if (max_iterations <= 0) invalid("max_iterations must be positive");
        if (fixed_iterations < 0) invalid("fixed_iterations must be >= 0");
        scene->scene.solver.cg_tolerance = tolerance;
        scene->scene.solver.cg_max_iterations = max_iterations;
        scene->scene.solver.cg_fixed_iterations = fixed_iterations;
    });
}

edgefem_status edgefem_scene_set_preconditioner(edgefem_scene* scene, const char* name) {
    return guard("edgefem_scene_set_preconditioner", [&] {
        require(scene, "scene");
        require(name, "name");
        scene->scene.solver.preconditioner = edgefem::parse_preconditioner(name);
    });
}

edgefem_status edgefem_scene_set_method(edgefem_scene* scene, int32_t method) {
    return guard("edgefem_scene_set_method", [&] {
        require(scene, "scene");
        if (method != EDGEFEM_METHOD_EDGE && method != EDGEFEM_METHOD_TET)
            invalid("method: " + std::to_string(method) +
                    " is not an edgefem_method (EDGEFEM_METHOD_EDGE 0, EDGEFEM_METHOD_TET 1)");
        scene->scene.method = method == EDGEFEM_METHOD_EDGE ? edgefem::Method::Edge : edgefem::Method::Tet;
    });
}

edgefem_status edgefem_scene_set_linear_solver(edgefem_scene* scene, int32_t solver) {
    return guard("edgefem_scene_set_linear_solver", [&] {
        require(scene, "scene");
        if (solver != EDGEFEM_LINEAR_CG && solver != EDGEFEM_LINEAR_DIRECT)
            invalid("solver: " + std::to_string(solver) +
                    " is not an edgefem_linear_solver (EDGEFEM_LINEAR_CG 0, EDGEFEM_LINEAR_DIRECT 1)");
        scene->scene.solver.linear_solver =
            solver == EDGEFEM_LINEAR_CG ? edgefem::LinearSolver::CG : edgefem::LinearSolver::Direct;
    });
}

edgefem_status edgefem_scene_set_newton(edgefem_scene* scene, double tolerance, int32_t max_iterations,
                                        int32_t load_steps) {
    return guard("edgefem_scene_set_newton", [&] {
        require(scene, "scene");
        if (!(std::isfinite(tolerance) && tolerance > 0))
            invalid("tolerance must be finite and positive, got " + std::to_string(tolerance));
        if (max_iterations < 1) invalid("max_iterations must be >= 1, got " + std::to_string(max_iterations));
        if (load_steps < 1) invalid("load_steps must be >= 1, got " + std::to_string(load_steps));
        scene->scene.solver.newton_tolerance = tolerance;
        scene->scene.solver.newton_max_iterations = max_iterations;
        scene->scene.solver.load_steps = load_steps;
    });
}

// ---- Regions ----

edgefem_status edgefem_scene_get_regions(const edgefem_scene* scene, int32_t* out, size_t count) {
    return guard("edgefem_scene_get_regions", [&] {
        require(scene, "scene");
        require(out, "out");
        const edgefem::Mesh& m = scene->scene.mesh;
        require_count(count, std::size_t(m.num_tets()), "out", "#T");
        for (edgefem::index_t t = 0; t < m.num_tets(); ++t) out[t] = m.tet_region(t);
    });
}

edgefem_status edgefem_scene_set_regions(edgefem_scene* scene, const int32_t* regions, size_t count) {
    return guard("edgefem_scene_set_regions", [&] {
        require(scene, "scene");
        edgefem::Mesh& m = scene->scene.mesh;
        if (count > 0) {
            require(regions, "regions");
            if (count != std::size_t(m.num_tets()))
                invalid("regions: count is " + std::to_string(count) + ", expected #T = " + std::to_string(m.num_tets()) +
                        " (or 0: every tet in region 0)");
        }
        m.region.assign(regions, regions ? regions + count : regions);
    });
}

edgefem_status edgefem_scene_set_region_material(edgefem_scene* scene, int32_t region, double young, double poisson,
                                                 double density) {
    return guard("edgefem_scene_set_region_material", [&] {
        require(scene, "scene");
        const edgefem::Material m{young, poisson, density};
        m.validate();
        scene->scene.materials.by_region[region] = m;
    });
}

// ---- Tagged surfaces and surface loads ----

namespace {
std::vector<edgefem::Triangle> tagged(const edgefem_scene* scene, int32_t tag) {
    return edgefem::tagged_triangles(scene->scene.mesh, {tag});
}

void add_load(edgefem_scene* scene, std::vector<edgefem::Triangle> triangles, double pressure, double tx, double ty,
              double tz, const double* times, const double* values, size_t key_count) {
    if (!std::isfinite(pressure)) invalid("pressure is not finite");
    const double t[3] = {tx, ty, tz};
    require_finite(t, 3, "traction", false);
    edgefem::SurfaceLoad load;
    load.triangles = std::move(triangles);
    load.pressure = pressure;
    load.traction = {tx, ty, tz};
    load.keyframes = keyframes(times, values, key_count, "keyframes");
    scene->scene.surface_loads.push_back(std::move(load));
}
}  // namespace

edgefem_status edgefem_scene_surface_count(const edgefem_scene* scene, int32_t tag, size_t* num_triangles) {
    return guard("edgefem_scene_surface_count", [&] {
        require(scene, "scene");
        require(num_triangles, "num_triangles");
        *num_triangles = tagged(scene, tag).size();
    });
}

edgefem_status edgefem_scene_get_surface(const edgefem_scene* scene, int32_t tag, int32_t* out, size_t count) {
    return guard("edgefem_scene_get_surface", [&] {
        require(scene, "scene");
        require(out, "out");
        const std::vector<edgefem::Triangle> tri = tagged(scene, tag);
        require_count(count, 3 * tri.size(), "out", "3 x (triangles tagged " + std::to_string(tag) + ")");
        for (std::size_t k = 0; k < tri.size(); ++k)
            for (int i = 0; i < 3; ++i) out[3 * k + i] = tri[k][i];
    });
}

edgefem_status edgefem_scene_surface_tag(const edgefem_scene* scene, const char* name, int32_t* tag) {
    return guard("edgefem_scene_surface_tag", [&] {
        require(scene, "scene");
        require(name, "name");
        require(tag, "tag");
        const std::vector<int> tags = edgefem::tags_named(scene->scene.mesh, name);
        if (tags.size() > 1)
            invalid("name: \"" + edgefem::printable(name) + "\" names " + std::to_string(tags.size()) +
                    " physical surfaces (tags " + std::to_string(tags[0]) + ", " + std::to_string(tags[1]) + ", ...)");
        *tag = tags[0];
    });
}

edgefem_status edgefem_scene_fix_surface(edgefem_scene* scene, int32_t tag) {
    return guard("edgefem_scene_fix_surface", [&] {
        require(scene, "scene");
        std::vector<edgefem::index_t>& fixed = scene->scene.fixed;
        const std::vector<edgefem::index_t> add = edgefem::triangle_vertices(tagged(scene, tag));
        fixed.insert(fixed.end(), add.begin(), add.end());
        std::sort(fixed.begin(), fixed.end());
        fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
    });
}

edgefem_status edgefem_scene_add_surface_load(edgefem_scene* scene, int32_t tag, double pressure, double tx, double ty,
                                              double tz, const double* times, const double* values, size_t key_count) {
    return guard("edgefem_scene_add_surface_load", [&] {
        require(scene, "scene");
        std::vector<edgefem::Triangle> tri;
        try {
            tri = edgefem::orient_outward(scene->scene.mesh, tagged(scene, tag));
        } catch (const edgefem::MeshError& e) {
            invalid("tag " + std::to_string(tag) + ": " + e.what());
        }
        add_load(scene, std::move(tri), pressure, tx, ty, tz, times, values, key_count);
    });
}

edgefem_status edgefem_scene_add_surface_load_triangles(edgefem_scene* scene, const int32_t* triangles, size_t count,
                                                        double pressure, double tx, double ty, double tz,
                                                        const double* times, const double* values, size_t key_count) {
    return guard("edgefem_scene_add_surface_load_triangles", [&] {
        require(scene, "scene");
        require(triangles, "triangles");
        if (count == 0 || count % 3 != 0)
            invalid("triangles: count is " + std::to_string(count) + ", expected a positive multiple of 3");
        const int32_t nv = scene->scene.mesh.num_vertices();
        std::vector<edgefem::Triangle> tri(count / 3);
        for (size_t i = 0; i < count; ++i) {
            if (triangles[i] < 0 || triangles[i] >= nv)
                invalid("triangles[" + std::to_string(i) + "] = " + std::to_string(triangles[i]) +
                        " is out of range [0, " + std::to_string(nv) + ")");
            tri[i / 3][i % 3] = triangles[i];
        }
        add_load(scene, std::move(tri), pressure, tx, ty, tz, times, values, key_count);
    });
}

edgefem_status edgefem_scene_clear_surface_loads(edgefem_scene* scene) {
    return guard("edgefem_scene_clear_surface_loads", [&] {
        require(scene, "scene");
        scene->scene.surface_loads.clear();
    });
}

// ---- Simulations ----

void edgefem_run_options_default(edgefem_run_options* out) {
    if (!out) return;
    *out = edgefem_run_options{nullptr, 0, nullptr, nullptr, 1, nullptr, nullptr};
}

namespace {
edgefem::RunOptions to_run_options(const edgefem_run_options* in) {
    edgefem::RunOptions run;
    if (!in) return run;
    if (in->backend) run.backend = in->backend;
    run.threads = in->threads;
    if (in->variant) run.variant = in->variant;
    if (in->schedule) run.schedule = in->schedule;
    if (in->adaptive != 0 && in->adaptive != 1)
        throw edgefem::InvalidArgument("run option adaptive: " + std::to_string(in->adaptive) + " (expected 0 or 1)");
    run.adaptive = in->adaptive == 1;
    if (in->ordering) run.ordering = in->ordering;
    if (in->layout) run.layout = in->layout;
    edgefem::validate(run);
    return run;
}
}  // namespace

edgefem_status edgefem_sim_create_with(const edgefem_scene* scene, const edgefem_run_options* run, edgefem_sim** out) {
    if (out) *out = nullptr;
    return guard("edgefem_sim_create_with", [&] {
        require(scene, "scene");
        require(out, "out");
        *out = new_handle<edgefem_sim>(edgefem::make_simulator<double>(scene->scene, to_run_options(run)));
    });
}

edgefem_status edgefem_sim_create(const edgefem_scene* scene, edgefem_sim** out) {
    if (out) *out = nullptr;
    return guard("edgefem_sim_create", [&] {
        require(scene, "scene");
        require(out, "out");
        *out = new_handle<edgefem_sim>(edgefem::make_simulator<double>(scene->scene, edgefem::RunOptions{}));
    });
}

void edgefem_sim_destroy(edgefem_sim* sim) { destroy_handle(sim); }

edgefem_status edgefem_sim_num_vertices(const edgefem_sim* sim, int32_t* out) {
    return guard("edgefem_sim_num_vertices", [&] {
        require(sim, "sim");
        require(out, "out");
        *out = sim->sim.num_vertices();
    });
}

edgefem_status edgefem_sim_step(edgefem_sim* sim, edgefem_step_stats* stats) {
    return guard("edgefem_sim_step", [&] {
        require(sim, "sim");
        const edgefem::StepStats& s = sim->sim.step();
        if (stats) {
            stats->force_ms = s.force_ms;
            stats->stiffness_ms = s.stiffness_ms;
            stats->solve_ms = s.solve_ms;
            stats->solver_iterations = s.solver_iterations;
            stats->newton_iterations = s.newton_iterations;
            stats->residual = s.residual;
            stats->inverted_tets = s.inverted_tets;
        }
    });
}

edgefem_status edgefem_sim_solve_static(edgefem_sim* sim, int32_t* converged) {
    return guard("edgefem_sim_solve_static", [&] {
        require(sim, "sim");
        const edgefem::StaticResult r = sim->sim.solve_static();
        if (converged) *converged = r.converged ? 1 : 0;
    });
}

edgefem_status edgefem_sim_set_external_forces(edgefem_sim* sim, const double* forces, size_t count) {
    return guard("edgefem_sim_set_external_forces", [&] {
        require(sim, "sim");
        require(forces, "forces");
        require_count(count, dofs(sim), "forces");
        require_finite(forces, count, "forces");
        std::copy(forces, forces + count, sim->sim.external_forces().begin());
    });
}

edgefem_status edgefem_sim_set_external_force(edgefem_sim* sim, int32_t vertex, double fx, double fy, double fz) {
    return guard("edgefem_sim_set_external_force", [&] {
        require(sim, "sim");
        const int32_t nv = sim->sim.num_vertices();
        if (vertex < 0 || vertex >= nv)
            invalid("vertex " + std::to_string(vertex) + " is out of range [0, " + std::to_string(nv) + ")");
        const double f[3] = {fx, fy, fz};
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(f[r]))
                invalid("the force on vertex " + std::to_string(vertex) + " is not finite (component " +
                        std::to_string(r) + ")");
        auto fe = sim->sim.external_forces();
        for (int r = 0; r < 3; ++r) fe[3 * std::size_t(vertex) + r] = f[r];
    });
}

edgefem_status edgefem_sim_clear_external_forces(edgefem_sim* sim) {
    return guard("edgefem_sim_clear_external_forces", [&] {
        require(sim, "sim");
        auto fe = sim->sim.external_forces();
        std::fill(fe.begin(), fe.end(), 0.0);
    });
}

edgefem_status edgefem_sim_get_positions(const edgefem_sim* sim, double* out, size_t count) {
    return guard("edgefem_sim_get_positions", [&] {
        require(sim, "sim");
        require(out, "out");
        require_count(count, dofs(sim), "out");
        const std::vector<double> x = sim->sim.positions();
        std::copy(x.begin(), x.end(), out);
    });
}

namespace {
// The const C handle reads spans the C++ API exposes only as non-const.
edgefem::OrderedSimulator<double>& mut(const edgefem_sim* sim) { return const_cast<edgefem_sim*>(sim)->sim; }
}  // namespace

edgefem_status edgefem_sim_get_displacement(const edgefem_sim* sim, double* out, size_t count) {
    return guard("edgefem_sim_get_displacement", [&] {
        require(sim, "sim");
        require(out, "out");
        require_count(count, dofs(sim), "out");
        const auto u = mut(sim).displacement();
        std::copy(u.begin(), u.end(), out);
    });
}

edgefem_status edgefem_sim_get_velocity(const edgefem_sim* sim, double* out, size_t count) {
    return guard("edgefem_sim_get_velocity", [&] {
        require(sim, "sim");
        require(out, "out");
        require_count(count, dofs(sim), "out");
        const auto v = mut(sim).velocity();
        std::copy(v.begin(), v.end(), out);
    });
}

edgefem_status edgefem_sim_set_displacement(edgefem_sim* sim, const double* u, size_t count) {
    return guard("edgefem_sim_set_displacement", [&] {
        require(sim, "sim");
        require(u, "u");
        require_count(count, dofs(sim), "u");
        require_finite(u, count, "u");
        std::copy(u, u + count, sim->sim.displacement().begin());
    });
}

edgefem_status edgefem_sim_set_velocity(edgefem_sim* sim, const double* v, size_t count) {
    return guard("edgefem_sim_set_velocity", [&] {
        require(sim, "sim");
        require(v, "v");
        require_count(count, dofs(sim), "v");
        require_finite(v, count, "v");
        std::copy(v, v + count, sim->sim.velocity().begin());
    });
}

edgefem_status edgefem_sim_energies(edgefem_sim* sim, edgefem_energies* out) {
    return guard("edgefem_sim_energies", [&] {
        require(sim, "sim");
        require(out, "out");
        const edgefem::Energies e = sim->sim.energies();
        out->kinetic = e.kinetic;
        out->elastic = e.elastic;
        out->gravity = e.gravity;
        out->total = e.total();
    });
}

edgefem_status edgefem_sim_time(const edgefem_sim* sim, double* time, int64_t* steps) {
    return guard("edgefem_sim_time", [&] {
        require(sim, "sim");
        if (time) *time = sim->sim.time();
        if (steps) *steps = sim->sim.step_index();
    });
}

edgefem_status edgefem_sim_save_checkpoint(edgefem_sim* sim, const char* path) {
    return checkpoint_call("edgefem_sim_save_checkpoint", sim, path,
                           [](edgefem::OrderedSimulator<double>& s, const char* p) { s.save_checkpoint(p); });
}

edgefem_status edgefem_sim_load_checkpoint(edgefem_sim* sim, const char* path) {
    return checkpoint_call("edgefem_sim_load_checkpoint", sim, path,
                           [](edgefem::OrderedSimulator<double>& s, const char* p) { s.load_checkpoint(p); });
}

}  // extern "C"

edgefem_status edgefem_embedding_create(const edgefem_scene* scene, const double* points, size_t count,
                                        edgefem_embedding** out) {
    if (out) *out = nullptr;
    return guard("edgefem_embedding_create", [&] {
        require(scene, "scene");
        require(points, "points");
        require(out, "out");
        if (count == 0 || count % 3 != 0)
            invalid("points: count is " + std::to_string(count) + ", expected 3 x (number of points) > 0");
        require_finite(points, count, "points");
        edgefem::Embedding e = edgefem::embed_points(scene->scene.mesh, std::span<const double>(points, count));
        *out = new_handle<edgefem_embedding>(edgefem_embedding{scene->scene.mesh, std::move(e)});
    });
}

void edgefem_embedding_destroy(edgefem_embedding* embedding) { destroy_handle(embedding); }

edgefem_status edgefem_embedding_num_points(const edgefem_embedding* embedding, size_t* num_points) {
    return guard("edgefem_embedding_num_points", [&] {
        require(embedding, "embedding");
        require(num_points, "num_points");
        *num_points = embedding->embedding.tet.size();
    });
}

edgefem_status edgefem_embedding_get_outside(const edgefem_embedding* embedding, double* out, size_t count) {
    return guard("edgefem_embedding_get_outside", [&] {
        require(embedding, "embedding");
        require(out, "out");
        const auto& d = embedding->embedding.outside;
        require_count(count, d.size(), "out", "the number of points");
        std::copy(d.begin(), d.end(), out);
    });
}

edgefem_status edgefem_sim_embedded_positions(const edgefem_sim* sim, const edgefem_embedding* embedding, double* out,
                                              size_t count) {
    return guard("edgefem_sim_embedded_positions", [&] {
        require(sim, "sim");
        require(embedding, "embedding");
        require(out, "out");
        const std::size_t points = embedding->embedding.tet.size();
        if (std::size_t(embedding->mesh.num_vertices()) != std::size_t(sim->sim.num_vertices()))
            invalid("embedding: made for a mesh of " + std::to_string(embedding->mesh.num_vertices()) +
                    " vertices, the simulation has " + std::to_string(sim->sim.num_vertices()));
        require_count(count, 3 * points, "out", "3 x (number of points)");
        const auto u = mut(sim).displacement();
        edgefem::embedded_positions<double>(embedding->mesh, embedding->embedding,
                                            std::span<const double>(u.data(), u.size()), std::span<double>(out, count));
    });
}

edgefem_status edgefem_vertex_normals(const int32_t* triangles, size_t num_triangles, const double* positions,
                                      size_t num_vertices, double* normals) {
    return guard("edgefem_vertex_normals", [&] {
        require(triangles, "triangles");
        require(positions, "positions");
        require(normals, "normals");
        std::vector<std::array<edgefem::index_t, 3>> tri(num_triangles);
        for (size_t k = 0; k < num_triangles; ++k)
            for (int i = 0; i < 3; ++i) {
                const int32_t v = triangles[3 * k + size_t(i)];
                if (v < 0 || size_t(v) >= num_vertices)
                    invalid("triangles[" + std::to_string(3 * k + size_t(i)) + "] = " + std::to_string(v) +
                            " (triangle " + std::to_string(k) + ") is not a vertex in [0, " +
                            std::to_string(num_vertices) + ")");
                tri[k][size_t(i)] = v;
            }
        require_finite(positions, 3 * num_vertices, "positions");
        const std::vector<double> n =
            edgefem::vertex_normals(tri, std::span<const double>(positions, 3 * num_vertices));
        std::copy(n.begin(), n.end(), normals);
    });
}
