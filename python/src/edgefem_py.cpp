// The `edgefem` Python module (pybind11; the extension edgefem._edgefem of
// the package edgefem): meshes, scenes, the Simulator with numpy views that
// alias its state, the elastic kernels, VTU output and a small benchmark
// entry point. Vectors are numpy arrays of shape (#V, 3).
//
// Hostile input (issues #26, #27): every array argument is checked for its
// exact shape and dtype (no flattening, wrapping or truncation) and vectors
// for NaN, each error naming the argument; a mesh is validated before any
// kernel touches it; what the simulator holds is read-only; a view never
// outlives its storage (setters copy into place, and a scene's mesh is not
// reallocated while a view of it is alive).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "lab/deformations.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/finite_input.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/retain_freed_memory.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/surface_load.hpp"
#include "edgefem/core/surface_selection.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "edgefem/parallel/run_options.hpp"

namespace py = pybind11;
using namespace edgefem;

namespace {

using InArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using InIndex = py::array_t<index_t, py::array::c_style | py::array::forcecast>;

// A (rows, cols) view of `data` that keeps `base` alive (no copy).
template <class T>
py::array view(T* data, py::ssize_t rows, py::ssize_t cols, py::handle base, bool writeable = true) {
    py::array a;
    if (cols == 1)
        a = py::array_t<T>({rows}, {py::ssize_t(sizeof(T))}, data, base);
    else
        a = py::array_t<T>({rows, cols}, {py::ssize_t(sizeof(T)) * cols, py::ssize_t(sizeof(T))}, data, base);
    if (!writeable) a.attr("flags").attr("writeable") = false;
    return a;
}

std::string shape_of(const py::array& a) {
    std::string out = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) out += (d ? ", " : "") + std::to_string(a.shape(d));
    return out + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_of(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// `obj` as a numpy array (a list becomes one); the error names the argument.
py::array as_array(py::handle obj, const std::string& name) {
    if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
    try {
        return py::module_::import("numpy").attr("asarray")(obj);
    } catch (py::error_already_set& e) {
        throw InvalidArgument(name + ": not convertible to a numpy array (" + e.what() + ")");
    }
}

void require_shape(const py::array& a, const std::string& name, py::ssize_t rows, py::ssize_t cols, const char* rows_name) {
    if (a.ndim() != 2 || a.shape(1) != cols || (rows >= 0 && a.shape(0) != rows))
        throw InvalidArgument(name + ": expected shape (" + (rows >= 0 ? std::to_string(rows) : rows_name) + ", " +
                              std::to_string(cols) + "), got " + shape_of(a));
}

// A (rows, 3) array of real numbers (rows < 0: any number) as float64, C
// order: float64 as given, other real floats and integers converted; any
// other dtype or shape is an error naming `name`. `finite`: NaN and infinity
// are errors too, naming the vertex.
InArray vectors_arg(py::handle obj, const std::string& name, py::ssize_t rows, bool finite) {
    const py::array a = as_array(obj, name);
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
        throw InvalidArgument(name + ": dtype " + dtype_of(a) +
                              " is not a real number type (expected float64; other floats and integers are converted)");
    require_shape(a, name, rows, 3, "N");
    InArray out = InArray::ensure(a);
    if (!out) throw py::error_already_set();
    if (finite) require_finite_vectors(std::span<const double>(out.data(), std::size_t(out.size())), name);
    return out;
}

// A (rows, cols) integer array of vertex indices (tets: (T, 4)) as index_t, refusing floats and
// any value a 32-bit index cannot hold (instead of truncating or wrapping).
// Whether the indices are in range is the mesh validation's to say.
std::vector<index_t> index_rows_arg(py::handle obj, const std::string& name, py::ssize_t cols) {
    const py::array a = as_array(obj, name);
    const char kind = a.dtype().kind();
    if (kind != 'i' && kind != 'u')
        throw InvalidArgument(name + ": dtype " + dtype_of(a) + " is not an integer type (vertex indices)");
    require_shape(a, name, -1, cols, cols == 4 ? "T" : "F");
    std::vector<index_t> tets(std::size_t(a.size()));
    const auto copy = [&](const auto& values) {
        for (std::size_t i = 0; i < tets.size(); ++i) {
            const auto v = values.data()[i];
            using V = std::decay_t<decltype(v)>;
            constexpr V hi = V(std::numeric_limits<index_t>::max());
            bool fits = v <= hi;
            if constexpr (std::is_signed_v<V>) fits = fits && v >= V(std::numeric_limits<index_t>::min());
            if (!fits)
                throw InvalidArgument(name + "[" + std::to_string(i / std::size_t(cols)) + ", " + std::to_string(i % std::size_t(cols)) +
                                      "] = " + std::to_string(v) + " does not fit a 32-bit vertex index");
            tets[i] = index_t(v);
        }
    };
    if (kind == 'u')
        copy(py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a));
    else
        copy(py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a));
    return tets;
}
std::vector<index_t> tets_arg(py::handle obj) { return index_rows_arg(obj, "tets", 4); }

py::array_t<double> new_vectors(const std::vector<double>& v) {
    py::array_t<double> out({py::ssize_t(v.size() / 3), py::ssize_t(3)});
    std::copy(v.begin(), v.end(), out.mutable_data());
    return out;
}

// Triangles (3 indices each) as a new (F, 3) int32 array.
py::array_t<std::int32_t> triangle_array(const std::vector<index_t>& v) {
    py::array_t<std::int32_t> a({py::ssize_t(v.size() / 3), py::ssize_t(3)});
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}
py::array_t<std::int32_t> triangle_array(const std::vector<std::array<index_t, 3>>& t) {
    std::vector<index_t> v;
    for (const auto& x : t) v.insert(v.end(), x.begin(), x.end());
    return triangle_array(v);
}
std::vector<std::array<index_t, 3>> triangles_arg(py::handle obj, const std::string& name) {
    const std::vector<index_t> t = index_rows_arg(obj, name, 3);
    std::vector<std::array<index_t, 3>> tri(t.size() / 3);
    for (std::size_t k = 0; k < tri.size(); ++k) tri[k] = {t[3 * k], t[3 * k + 1], t[3 * k + 2]};
    return tri;
}

Mesh mesh_from_arrays(py::handle X, py::handle tets, std::optional<std::vector<int>> region) {
    const InArray x = vectors_arg(X, "X", -1, false);
    Mesh m;
    m.X.assign(x.data(), x.data() + x.size());
    m.tets = tets_arg(tets);
    if (region) {
        if (region->size() != std::size_t(m.num_tets()))
            throw InvalidArgument("region: expected one id per tet (" + std::to_string(m.num_tets()) + "), got " +
                                  std::to_string(region->size()));
        m.region = *region;
    }
    return m;
}

// A mesh's arrays as numpy views kept alive by `owner` (read-only unless
// `writeable`; tets always are), and its repr: shared by Mesh and MeshView.
py::array mesh_X(const Mesh& me, py::handle owner, bool writeable) {
    return view(const_cast<double*>(me.X.data()), me.num_vertices(), 3, owner, writeable);
}
py::array mesh_tets(const Mesh& me, py::handle owner) {
    return view(const_cast<index_t*>(me.tets.data()), me.num_tets(), 4, owner, false);
}
std::string mesh_repr(const char* cls, const Mesh& me) {
    return std::string("<edgefem.") + cls + " " + std::to_string(me.num_vertices()) + " vertices, " +
           std::to_string(me.num_tets()) + " tets>";
}

// Replaces a scene's mesh from Python. Same counts: copied into the arrays
// numpy views may show (they then show the new mesh). Other counts
// reallocate, refused while a Mesh object for the scene's mesh (which every
// view of it keeps alive) exists: a view would point into freed memory.
void set_scene_mesh(Scene& s, const Mesh& m) {
    Mesh& old = s.mesh;
    if (m.num_vertices() == old.num_vertices() && m.num_tets() == old.num_tets()) {
        if (&m == &old) return;
        std::copy(m.X.begin(), m.X.end(), old.X.begin());
        std::copy(m.tets.begin(), m.tets.end(), old.tets.begin());
        old.region = m.region;
        old.surfaces = m.surfaces;
        old.source = m.source;
        return;
    }
    if (py::detail::get_object_handle(&old, py::detail::get_type_info(typeid(Mesh))))
        throw InvalidArgument("Scene.mesh: the new mesh has " + std::to_string(m.num_vertices()) + " vertices and " +
                              std::to_string(m.num_tets()) + " tets, the scene's " +
                              std::to_string(old.num_vertices()) + " and " + std::to_string(old.num_tets()) +
                              ", and a Mesh object or numpy array viewing the scene's mesh is still alive (it would "
                              "point into freed memory): delete those references first, or build a new Scene");
    old = m;
}

// What a Simulator holds, seen from Python: read-only (no setters, numpy
// arrays flagged read-only); copy() gives objects of one's own. Each view
// keeps the simulator alive.
struct MeshView {
    const Mesh* mesh;
};
struct SceneView {
    const Scene* scene;
};

py::list prescribed_list(const Scene& s) {
    py::list out;
    for (const auto& p : s.prescribed) out.append(py::make_tuple(p.vertex, p.target));
    return out;
}

// The elastic kernels on their own, owning a copy of the mesh (the operator
// keeps a reference to it).
struct ElasticModel {
    // Validated first (as a Simulator's scene is): no kernel sees a bad mesh.
    ElasticModel(Mesh m, const Materials& mat, ModelKind kind, Method method, const RunOptions& run)
        : mesh((check_mesh(m), std::move(m))), op(make_run_factory<double>(run, make_run_executor(run))(mesh, mat, kind, method)) {}
    ElasticModel(const ElasticModel&) = delete;
    ElasticModel& operator=(const ElasticModel&) = delete;
    std::size_t dofs() const { return 3 * std::size_t(mesh.num_vertices()); }

    Mesh mesh;
    std::unique_ptr<ElasticOperator<double>> op;
    bool have_state = false, have_stiffness = false;
};

using clock_type = std::chrono::steady_clock;

// Times `call` for about `seconds` after a short warm-up; returns sorted ns.
template <class Call>
std::vector<double> time_calls(double seconds, Call&& call) {
    // As `edgefem bench`: a bounded budget, and at most 2^22 stored samples
    // (32 MiB), so a tiny mesh and a long budget cannot eat the memory.
    if (!(seconds > 0) || !(seconds <= 3600))
        throw InvalidArgument("seconds must be positive and at most 3600, got " + std::to_string(seconds));
    constexpr std::size_t kMaxCalls = std::size_t(1) << 22;
    const auto budget = std::chrono::duration<double>(seconds);
    for (const auto w0 = clock_type::now();;) {
        call();
        if (clock_type::now() - w0 >= 0.05 * budget) break;
    }
    std::vector<double> ns;
    for (const auto start = clock_type::now();
         ns.size() < 5 || (ns.size() < kMaxCalls && clock_type::now() - start < budget);) {
        const auto t0 = clock_type::now();
        call();
        ns.push_back(std::chrono::duration<double, std::nano>(clock_type::now() - t0).count());
    }
    std::sort(ns.begin(), ns.end());
    return ns;
}

double median(const std::vector<double>& v) {
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The run options from the keyword arguments (the same names and defaults
// as RunOptions, the CLI and the C API).
RunOptions run_options(const std::string& backend, int threads, const std::string& variant, const std::string& schedule,
                       bool adaptive, const std::string& ordering, const std::string& layout) {
    RunOptions run;
    run.backend = backend;
    run.threads = threads;
    run.variant = variant;
    run.schedule = schedule;
    run.adaptive = adaptive;
    run.ordering = ordering;
    run.layout = layout;
    validate(run);
    return run;
}

}  // namespace

PYBIND11_MODULE(_edgefem, m) {
    m.doc() = "edgefem: edge-based StVK tetrahedral FEM (meshes, scenes, simulator, kernels).";
    m.attr("__version__") = EDGEFEM_VERSION;
    m.attr("has_parallel") = true;  // the CPU back-end's threads (always built)

    // Exceptions: edgefem.Error and its subclasses, with the C++ message.
    static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
    static py::exception<InvalidArgument> invalid(m, "InvalidArgument", error.ptr());
    static py::exception<MeshError> mesh_error(m, "MeshError", error.ptr());
    static py::exception<SimulationError> sim_error(m, "SimulationError", error.ptr());
    static py::exception<CheckpointError> checkpoint_error(m, "CheckpointError", error.ptr());
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const SimulationError& e) {
            sim_error(e.what());
        } catch (const MeshError& e) {
            mesh_error(e.what());
        } catch (const CheckpointError& e) {
            checkpoint_error(e.what());
        } catch (const InvalidArgument& e) {
            invalid(e.what());
        } catch (const Error& e) {
            error(e.what());
        }
    });

    py::enum_<ModelKind>(m, "ModelKind").value("FE", ModelKind::FE).value("SN", ModelKind::SN);
    py::enum_<Method>(m, "Method").value("Edge", Method::Edge).value("Tet", Method::Tet);
    py::enum_<Integrator>(m, "Integrator")
        .value("Explicit", Integrator::Explicit)
        .value("SemiImplicit", Integrator::SemiImplicit)
        .value("Implicit", Integrator::Implicit)
        .value("Newmark", Integrator::Newmark)
        .value("NewmarkLinear", Integrator::NewmarkLinear)
        .value("GeneralizedAlpha", Integrator::GeneralizedAlpha)
        .value("GeneralizedAlphaLinear", Integrator::GeneralizedAlphaLinear)
        .value("Bdf2", Integrator::Bdf2)
        .value("Bdf2Linear", Integrator::Bdf2Linear)
        .value("Verlet", Integrator::Verlet);
    py::class_<Keyframe>(m, "Keyframe", "A value at a time (s): keyframes are linear in between.")
        .def(py::init([](double t, double v) { return Keyframe{t, v}; }), py::arg("time"), py::arg("value"))
        .def_readwrite("time", &Keyframe::time)
        .def_readwrite("value", &Keyframe::value);
    py::class_<IntegratorParameters>(m, "IntegratorParameters", "Newmark's beta and gamma, generalized-alpha's rho_inf.")
        .def(py::init<>())
        .def_readwrite("newmark_beta", &IntegratorParameters::newmark_beta)
        .def_readwrite("newmark_gamma", &IntegratorParameters::newmark_gamma)
        .def_readwrite("rho_inf", &IntegratorParameters::rho_inf);
    py::enum_<LinearSolver>(m, "LinearSolver").value("CG", LinearSolver::CG).value("Direct", LinearSolver::Direct);

    // ---- meshes ----
    py::class_<Mesh> mesh_class(m, "Mesh", "Rest positions X (#V, 3) and tets (#T, 4); both are views into the mesh.");
    mesh_class.def(py::init(&mesh_from_arrays), py::arg("X"), py::arg("tets"), py::arg("region") = py::none(),
             "A mesh from arrays, copied: X of shape (N, 3), float64 (other real floats and integers are "
             "converted); tets of shape (T, 4), any integer dtype whose values fit 32 bits (floats are refused). "
             "Not validated: call validate(); every kernel, Simulator and write_vtu validates it.")
        .def_property(
            "X", [](py::object self) { return mesh_X(self.cast<Mesh&>(), self, true); },
            [](Mesh& me, py::handle X) {
                const InArray x = vectors_arg(X, "X", me.num_vertices(), false);
                std::copy(x.data(), x.data() + x.size(), me.X.begin());  // into place: views stay valid
            },
            "(N, 3) view; assigning copies into it (same shape).")
        .def_property_readonly("tets", [](py::object self) { return mesh_tets(self.cast<Mesh&>(), self); })
        .def_readwrite("region", &Mesh::region)
        .def_property_readonly("surface_triangles", [](const Mesh& me) { return triangle_array(me.surfaces.vertices); },
                               "The mesh file's tagged boundary triangles (F, 3), in the file's winding (a copy).")
        .def_property_readonly("surface_tags", [](const Mesh& me) { return me.surfaces.tag; },
                               "The tag of each tagged triangle (Gmsh physical, TetGen marker, MEDIT reference).")
        .def_property_readonly("surface_names", [](const Mesh& me) { return me.surfaces.names; },
                               "Gmsh physical surface names: {tag: name}.")
        .def_property_readonly("num_vertices", &Mesh::num_vertices)
        .def_property_readonly("num_tets", &Mesh::num_tets)
        .def(
            "validate",
            [](Mesh& me, bool fix_orientation) {
                ValidationOptions o;
                o.fix_orientation = fix_orientation;
                return validate_mesh(me, o).warnings;
            },
            py::arg("fix_orientation") = false,
            "Checks the mesh (raises MeshError naming the element); returns warnings.")
        .def("copy", [](const Mesh& me) { return Mesh(me); })
        .def("__repr__", [](const Mesh& me) { return mesh_repr("Mesh", me); });
    py::class_<MeshView>(m, "MeshView", "The mesh a Simulator holds: read-only arrays; copy() gives a Mesh.")
        .def_property_readonly("X", [](py::object self) { return mesh_X(*self.cast<MeshView&>().mesh, self, false); })
        .def_property_readonly("tets", [](py::object self) { return mesh_tets(*self.cast<MeshView&>().mesh, self); })
        .def_property_readonly("region", [](const MeshView& v) { return v.mesh->region; })
        .def_property_readonly("num_vertices", [](const MeshView& v) { return v.mesh->num_vertices(); })
        .def_property_readonly("num_tets", [](const MeshView& v) { return v.mesh->num_tets(); })
        .def("copy", [](const MeshView& v) { return Mesh(*v.mesh); })
        .def("__repr__", [](const MeshView& v) { return mesh_repr("MeshView", *v.mesh); });
    // Wherever a Mesh is taken (write_vtu, ElasticModel, ...), a MeshView is
    // too, as a copy.
    mesh_class.def(py::init([](const MeshView& v) { return Mesh(*v.mesh); }), py::arg("view"));
    py::implicitly_convertible<MeshView, Mesh>();

    m.def(
        "read_mesh",
        [](const std::string& path, bool validate) {
            Mesh mesh = is_box_spec(path) ? make_box_from_spec(path) : read_mesh(path);
            if (validate) validate_mesh(mesh);
            return mesh;
        },
        py::arg("path"), py::arg("validate") = true,
        "Reads a TetGen .node/.ele (or prefix), Gmsh .msh, MEDIT .mesh, Vega .veg, or 'box:NXxNYxNZ'.");
    m.def("retain_freed_memory", &retain_freed_memory,
          "Keeps the memory this process frees for its own reuse (glibc: malloc's trim threshold 512 MiB, mmap "
          "threshold 32 MiB) rather than handing it back, where the AMG's refreshes would fault it in again "
          "(docs/parallel.md). Process-wide; the peak memory does not change. True where it changed malloc's "
          "settings; False without glibc or where GLIBC_TUNABLES sets a glibc.malloc tunable.");
    m.def("make_box", &make_box, py::arg("nx"), py::arg("ny"), py::arg("nz"), py::arg("cell") = 0.01,
          "A box of nx x ny x nz cubes of side `cell` (6 tets each), centred at the origin.");
    m.def("make_box_of_size", &make_box_of_size, py::arg("target_tets"),
          "A box of about `target_tets` tets with the paper box's 5:2.5:2 aspect.");

    // ---- output ----
    m.def(
        "write_vtu",
        [](const std::string& path, const Mesh& mesh, py::object displacement, py::object force, py::object velocity,
           const std::string& format) {
            if (format != "binary" && format != "ascii")
                throw InvalidArgument("write_vtu: format: expected 'binary' or 'ascii', got '" + printable(format) + "'");
            VtuFields f;
            // Not required finite: a blown-up state may be written to look at.
            InArray u, fo, v;
            if (!displacement.is_none())
                u = vectors_arg(displacement, "displacement", mesh.num_vertices(), false), f.displacement = u.data();
            if (!force.is_none()) fo = vectors_arg(force, "force", mesh.num_vertices(), false), f.force = fo.data();
            if (!velocity.is_none())
                v = vectors_arg(velocity, "velocity", mesh.num_vertices(), false), f.velocity = v.data();
            // checks the connectivity before writing
            write_vtu(path, mesh, f, format == "ascii" ? VtuFormat::Ascii : VtuFormat::Binary);
        },
        py::arg("path"), py::arg("mesh"), py::arg("displacement") = py::none(), py::arg("force") = py::none(),
        py::arg("velocity") = py::none(), py::arg("format") = "binary",
        "Writes a VTK .vtu frame (points X + displacement): format 'binary' (zlib-compressed appended data, the "
        "default) or 'ascii'.");
    py::class_<PvdSeries>(m, "PvdSeries", "A .pvd series: add(time, vtu_path) per frame; written on write()/close.")
        .def(py::init<std::string>(), py::arg("pvd_path"))
        .def("add", &PvdSeries::add, py::arg("time"), py::arg("vtu_path"))
        .def("write", &PvdSeries::write)
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](PvdSeries& s, py::args) { s.write(); });

    // ---- scenes ----
    py::class_<Material>(m, "Material")
        .def(py::init([](double young, double poisson, double density) { return Material{young, poisson, density}; }),
             py::arg("young") = 1e5, py::arg("poisson") = 0.3, py::arg("density") = 1000.0)
        .def_readwrite("young", &Material::young)
        .def_readwrite("poisson", &Material::poisson)
        .def_readwrite("density", &Material::density)
        .def_property_readonly("lame_lambda", &Material::lambda)
        .def_property_readonly("lame_mu", &Material::mu)
        .def("validate", &Material::validate)
        .def("__repr__", [](const Material& x) {
            return "<edgefem.Material young=" + std::to_string(x.young) + " poisson=" + std::to_string(x.poisson) +
                   " density=" + std::to_string(x.density) + ">";
        });

    py::class_<SolverSettings>(m, "SolverSettings")
        .def(py::init<>())
        .def_readwrite("linear_solver", &SolverSettings::linear_solver)
        .def_property(
            "preconditioner", [](const SolverSettings& s) { return std::string(to_string(s.preconditioner)); },
            [](SolverSettings& s, const std::string& name) { s.preconditioner = parse_preconditioner(name); },
            "CG's preconditioner: \"auto\" (default: block-Jacobi, AMG once a solve needs more than "
            "auto_amg_iterations, back where AMG costs more), \"block-jacobi\" or \"amg\" (docs/solvers.md)")
        .def_readwrite("auto_amg_iterations", &SolverSettings::auto_amg_iterations)
        .def_readwrite("amg_refresh_interval", &SolverSettings::amg_refresh_interval)
        .def_readwrite("cg_tolerance", &SolverSettings::cg_tolerance)
        .def_readwrite("warm_start", &SolverSettings::warm_start)
        .def_readwrite("cg_max_iterations", &SolverSettings::cg_max_iterations)
        .def_readwrite("cg_fixed_iterations", &SolverSettings::cg_fixed_iterations)
        .def_readwrite("definite_stiffness", &SolverSettings::definite_stiffness)
        .def_readwrite("newton_tolerance", &SolverSettings::newton_tolerance)
        .def_readwrite("newton_max_iterations", &SolverSettings::newton_max_iterations)
        .def_readwrite("load_steps", &SolverSettings::load_steps)
        .def_readwrite("max_step_halvings", &SolverSettings::max_step_halvings)
        .def_readwrite("stiffness_interval", &SolverSettings::stiffness_interval)
        .def_readwrite("fail_on_unconverged", &SolverSettings::fail_on_unconverged)
        .def_readwrite("max_energy_growth", &SolverSettings::max_energy_growth);

    py::class_<SurfaceLoad>(m, "SurfaceLoad",
                            "A pressure (Pa, positive pushes into the body) and a traction (Pa, a fixed vector per area) "
                            "on triangles (F, 3) wound outward, scaled by keyframes; dead loads on the rest surface.")
        .def(py::init([](py::handle triangles, double pressure, std::array<double, 3> traction,
                         std::vector<Keyframe> keyframes) {
                 SurfaceLoad l;
                 l.triangles = triangles_arg(triangles, "triangles");
                 l.pressure = pressure;
                 l.traction = traction;
                 l.keyframes = std::move(keyframes);
                 return l;
             }),
             py::arg("triangles"), py::arg("pressure") = 0.0, py::arg("traction") = std::array<double, 3>{0, 0, 0},
             py::arg("keyframes") = std::vector<Keyframe>{})
        .def_property(
            "triangles", [](const SurfaceLoad& l) { return triangle_array(l.triangles); },
            [](SurfaceLoad& l, py::handle t) { l.triangles = triangles_arg(t, "triangles"); }, "(F, 3) int32 (a copy).")
        .def_readwrite("pressure", &SurfaceLoad::pressure)
        .def_readwrite("traction", &SurfaceLoad::traction)
        .def_readwrite("keyframes", &SurfaceLoad::keyframes);
    py::class_<Scene>(m, "Scene", "Mesh, material, loads, constraints and integrator settings (docs/scenes.md).")
        .def(py::init([](Mesh mesh, const Material& material, std::vector<index_t> fixed,
                         std::array<double, 3> gravity, double dt, Integrator integrator, ModelKind model,
                         Method method) {
                 Scene s;
                 s.mesh = std::move(mesh);
                 s.materials = material;
                 s.fixed = std::move(fixed);
                 s.gravity = gravity;
                 s.dt = dt;
                 s.integrator = integrator;
                 s.model = model;
                 s.method = method;
                 return s;
             }),
             py::arg("mesh"), py::arg("material") = Material{}, py::arg("fixed") = std::vector<index_t>{},
             py::arg("gravity") = std::array<double, 3>{0, 0, 0}, py::arg("dt") = 1e-3,
             py::arg("integrator") = Integrator::SemiImplicit, py::arg("model") = ModelKind::FE,
             py::arg("method") = Method::Edge)
        .def_static("from_json", [](const std::string& path) { return load_scene(path).scene; }, py::arg("path"),
                    "Reads and validates a JSON scene file.")
        .def_property("mesh", [](Scene& s) -> Mesh& { return s.mesh; }, &set_scene_mesh,
                      py::return_value_policy::reference_internal,
                      "The scene's mesh (its arrays are views). Assigning copies into it when the counts match; "
                      "a mesh of other counts replaces it only while no view of the old one is alive.")
        .def_property(
            "material", [](const Scene& s) { return s.materials.fallback; },
            [](Scene& s, const Material& mat) { s.materials = Materials(mat); },
            "The material of every region (setting it drops per-region materials).")
        .def("set_region_material", [](Scene& s, int region, const Material& mat) { s.materials.by_region[region] = mat; },
             py::arg("region"), py::arg("material"))
        .def_readwrite("model", &Scene::model)
        .def_readwrite("method", &Scene::method)
        .def_readwrite("gravity", &Scene::gravity)
        .def_readwrite("rayleigh_alpha", &Scene::rayleigh_alpha)
        .def_readwrite("rayleigh_beta", &Scene::rayleigh_beta)
        .def_readwrite("fixed", &Scene::fixed)
        .def_property(
            "prescribed", &prescribed_list,
            [](Scene& s, const std::vector<std::pair<index_t, std::array<double, 3>>>& ps) {
                s.prescribed.clear();
                for (const auto& [v, t] : ps) s.prescribed.push_back({v, t});
            },
            "List of (vertex, (x, y, z)) target positions.")
        .def_readwrite("prescribed_steps", &Scene::prescribed_steps)
        .def_readwrite("integrator", &Scene::integrator)
        .def_readwrite("integrator_parameters", &Scene::integrator_parameters)
        .def_readwrite("prescribed_keyframes", &Scene::prescribed_keyframes)
        .def_readwrite("load", &Scene::load, "External load, 3 x #V values (N; empty: none).")
        .def_readwrite("load_keyframes", &Scene::load_keyframes)
        .def_readwrite("surface_loads", &Scene::surface_loads, "Pressure and traction loads (a list of SurfaceLoad, copied).")
        .def_readwrite("initial_displacement", &Scene::initial_displacement, "3 x #V values (empty: rest).")
        .def_readwrite("initial_velocity", &Scene::initial_velocity, "3 x #V values (empty: rest).")
        .def_readwrite("dt", &Scene::dt)
        .def_readwrite("steps", &Scene::steps)
        .def_readwrite("solver", &Scene::solver)
        .def_readwrite("count_inverted_tets", &Scene::count_inverted_tets)
        .def("validate", &Scene::validate)
        .def("copy", [](const Scene& s) { return Scene(s); });
    py::class_<SceneView>(m, "SceneView",
                          "The scene a Simulator holds: read-only (its mesh's arrays too); copy() gives a Scene.")
        .def_property_readonly("mesh", py::cpp_function([](const SceneView& v) { return MeshView{&v.scene->mesh}; },
                                                        py::keep_alive<0, 1>()))
        .def_property_readonly("material", [](const SceneView& v) { return v.scene->materials.fallback; })
        .def_property_readonly("model", [](const SceneView& v) { return v.scene->model; })
        .def_property_readonly("method", [](const SceneView& v) { return v.scene->method; })
        .def_property_readonly("gravity", [](const SceneView& v) { return v.scene->gravity; })
        .def_property_readonly("rayleigh_alpha", [](const SceneView& v) { return v.scene->rayleigh_alpha; })
        .def_property_readonly("rayleigh_beta", [](const SceneView& v) { return v.scene->rayleigh_beta; })
        .def_property_readonly("fixed", [](const SceneView& v) { return v.scene->fixed; })
        .def_property_readonly("prescribed", [](const SceneView& v) { return prescribed_list(*v.scene); })
        .def_property_readonly("prescribed_steps", [](const SceneView& v) { return v.scene->prescribed_steps; })
        .def_property_readonly("integrator", [](const SceneView& v) { return v.scene->integrator; })
        .def_property_readonly("dt", [](const SceneView& v) { return v.scene->dt; })
        .def_property_readonly("steps", [](const SceneView& v) { return v.scene->steps; })
        .def_property_readonly("solver", [](const SceneView& v) { return v.scene->solver; }, "A copy.")
        .def_property_readonly("count_inverted_tets", [](const SceneView& v) { return v.scene->count_inverted_tets; })
        .def("copy", [](const SceneView& v) { return Scene(*v.scene); });
    m.def("load_scene", [](const std::string& path) { return load_scene(path).scene; }, py::arg("path"),
          "Scene.from_json(path).");
    m.def("default_scene", &default_scene, "The built-in beam scene of `edgefem simulate`.");

    // ---- the simulator ----
    py::class_<StepStats>(m, "StepStats")
        .def_readonly("force_ms", &StepStats::force_ms)
        .def_readonly("stiffness_ms", &StepStats::stiffness_ms)
        .def_readonly("solve_ms", &StepStats::solve_ms)
        .def_readonly("solver_iterations", &StepStats::solver_iterations)
        .def_readonly("symbolic_analyses", &StepStats::symbolic_analyses)
        .def_readonly("preconditioner_refreshes", &StepStats::preconditioner_refreshes)
        .def_readonly("newton_iterations", &StepStats::newton_iterations)
        .def_readonly("residual", &StepStats::residual)
        .def_readonly("negative_curvature", &StepStats::negative_curvature)
        .def_readonly("inverted_tets", &StepStats::inverted_tets)
        .def_readonly("halvings", &StepStats::halvings)
        .def_readonly("substep_depth", &StepStats::substep_depth)
        .def_readonly("unconverged_solves", &StepStats::unconverged_solves)
        .def_readonly("newton_round_off", &StepStats::newton_round_off)
        .def_readonly("energy_growth", &StepStats::energy_growth)
        .def("__repr__", [](const StepStats& s) {
            return "<edgefem.StepStats iterations=" + std::to_string(s.solver_iterations) +
                   " residual=" + std::to_string(s.residual) + ">";
        });
    py::class_<Energies>(m, "Energies")
        .def_readonly("kinetic", &Energies::kinetic)
        .def_readonly("elastic", &Energies::elastic)
        .def_readonly("gravity", &Energies::gravity)
        .def_property_readonly("total", &Energies::total);
    py::class_<StaticResult>(m, "StaticResult")
        .def_readonly("newton_iterations", &StaticResult::newton_iterations)
        .def_readonly("load_steps", &StaticResult::load_steps)
        .def_readonly("residual", &StaticResult::residual)
        .def_readonly("converged", &StaticResult::converged);

    using Sim = OrderedSimulator<double>;
    auto vec_view = [](std::span<double> (Sim::*get)()) {
        return [get](py::object self) {
            Sim& s = self.cast<Sim&>();
            return view((s.*get)().data(), s.num_vertices(), 3, self);
        };
    };
    auto vec_set = [](std::span<double> (Sim::*get)(), const char* what) {
        return [get, what](Sim& s, py::handle a) {
            const InArray in = vectors_arg(a, what, s.num_vertices(), true);
            std::copy(in.data(), in.data() + in.size(), (s.*get)().begin());
        };
    };
    py::class_<Sim>(m, "Simulator",
                    "Steps a Scene (double precision). displacement, velocity and external_forces are (#V, 3) "
                    "numpy views of the simulator's own state: writing into them changes the simulation.")
        .def(py::init([](const Scene& scene, const std::string& backend, int threads, const std::string& variant,
                         const std::string& schedule, bool adaptive, const std::string& ordering,
                         const std::string& layout) {
                 return make_simulator<double>(scene,
                                               run_options(backend, threads, variant, schedule, adaptive, ordering, layout));
             }),
             py::arg("scene"), py::arg("backend") = RunOptions{}.backend, py::arg("threads") = RunOptions{}.threads,
             py::arg("variant") = RunOptions{}.variant, py::arg("schedule") = RunOptions{}.schedule,
             py::arg("adaptive") = RunOptions{}.adaptive, py::arg("ordering") = RunOptions{}.ordering,
             py::arg("layout") = RunOptions{}.layout,
             "The run options, with the CLI's names and defaults: backend 'auto' (every core), 'serial', 'omp', "
             "'tbb', 'pool' or 'reference'; threads (0: all); variant; schedule; adaptive (loops run serially "
             "where that was faster in sum; same results); ordering (the internal vertex numbering: 'rcm', "
             "'input', ...; the views stay in the mesh's numbering); layout ('tet-local' or 'tsep-list').")
        .def("step", &Sim::step, py::return_value_policy::copy, py::call_guard<py::gil_scoped_release>(),
             "Advances by scene.dt; raises SimulationError on failure.")
        .def(
            "run",
            [](Sim& s, int steps) {
                if (steps < 0) throw InvalidArgument("run: steps must be >= 0, got " + std::to_string(steps));
                py::gil_scoped_release release;
                for (int k = 0; k < steps; ++k) s.step();
                return s.last_stats();
            },
            py::arg("steps"), "step() `steps` times; returns the last step's stats.")
        .def("solve_static", [](Sim& s) { return s.solve_static(); }, py::call_guard<py::gil_scoped_release>())
        .def("save_checkpoint", &Sim::save_checkpoint, py::arg("path"), py::call_guard<py::gil_scoped_release>(),
             "Writes the whole state to `path`, whole or not at all (docs/api.md, \"Checkpoints\"); raises "
             "edgefem.Error naming the file when it cannot be written.")
        .def("load_checkpoint", &Sim::load_checkpoint, py::arg("path"), py::call_guard<py::gil_scoped_release>(),
             "Reads a checkpoint of this scene, integrator, solver and ordering: stepping on continues bitwise as "
             "if the run had not stopped. Raises CheckpointError naming the file and the problem (unreadable, "
             "truncated, corrupt, written for another simulator), the state unchanged.")
        .def("energies", &Sim::energies)
        .def("positions", [](const Sim& s) { return new_vectors(s.positions()); }, "X + u (a new array).")
        .def_property("displacement", vec_view(&Sim::displacement), vec_set(&Sim::displacement, "displacement"))
        .def_property("velocity", vec_view(&Sim::velocity), vec_set(&Sim::velocity, "velocity"))
        .def_property("external_forces", vec_view(&Sim::external_forces),
                      vec_set(&Sim::external_forces, "external_forces"))
        .def_property_readonly("forces",
                               [](py::object self) {
                                   Sim& s = self.cast<Sim&>();
                                   auto f = s.forces();
                                   return view(const_cast<double*>(f.data()), s.num_vertices(), 3, self, false);
                               },
                               "Internal elastic forces of the last evaluation (read-only view).")
        .def_property_readonly("lumped_mass",
                               [](py::object self) {
                                   Sim& s = self.cast<Sim&>();
                                   auto mm = s.lumped_mass();
                                   return view(const_cast<double*>(mm.data()), s.num_vertices(), 1, self, false);
                               })
        .def_property_readonly("scene",
                               py::cpp_function([](const Sim& s) { return SceneView{&s.scene()}; },
                                                py::keep_alive<0, 1>()),
                               "The scene it runs, read-only (copy() gives a Scene to change and run anew).")
        .def_property_readonly("num_vertices", &Sim::num_vertices)
        .def_property_readonly("step_index", &Sim::step_index)
        .def_property_readonly("time", &Sim::time)
        .def_property_readonly("last_stats", &Sim::last_stats, py::return_value_policy::copy);

    // ---- kernels ----
    py::class_<ElasticModel>(m, "ElasticModel",
                             "The elastic kernels on a mesh: energy, forces f = dW/du, and K x, for displacements "
                             "u = x - X of shape (#V, 3).")
        .def(py::init([](const Mesh& mesh, const Material& material, ModelKind model, Method method,
                         const std::string& backend, int threads, const std::string& variant, const std::string& layout) {
                 return std::make_unique<ElasticModel>(
                     mesh, Materials(material), model, method,
                     run_options(backend, threads, variant, RunOptions{}.schedule, false, "input", layout));
             }),
             py::arg("mesh"), py::arg("material") = Material{}, py::arg("model") = ModelKind::FE,
             py::arg("method") = Method::Edge, py::arg("backend") = RunOptions{}.backend,
             py::arg("threads") = RunOptions{}.threads, py::arg("variant") = RunOptions{}.variant,
             py::arg("layout") = RunOptions{}.layout,
             "The kernels on the mesh as numbered (no ordering), with the run options' back-end, threads, "
             "variant and layout (their defaults as Simulator's).")
        .def_property_readonly("num_vertices", [](const ElasticModel& em) { return em.mesh.num_vertices(); })
        .def(
            "energy", [](ElasticModel& em, py::handle u_in) {
                const InArray u = vectors_arg(u_in, "u", em.mesh.num_vertices(), true);
                return em.op->energy(u.data());
            },
            py::arg("u"), "W(u).")
        .def(
            "forces",
            [](ElasticModel& em, py::handle u_in) {
                const InArray u = vectors_arg(u_in, "u", em.mesh.num_vertices(), true);
                py::array_t<double> f({py::ssize_t(em.mesh.num_vertices()), py::ssize_t(3)});
                const double W = em.op->forces(u.data(), f.mutable_data(), true);
                em.have_state = true;
                em.have_stiffness = false;
                return py::make_tuple(W, f);
            },
            py::arg("u"), "(W, f) with f = dW/du, shape (#V, 3).")
        .def(
            "build_stiffness",
            [](ElasticModel& em, py::handle u_in, bool definite) {
                const InArray u = vectors_arg(u_in, "u", em.mesh.num_vertices(), true);
                std::vector<double> f(em.dofs());
                em.op->forces(u.data(), f.data(), false);
                em.op->build_stiffness(definite);
                em.have_state = em.have_stiffness = true;
            },
            py::arg("u"), py::arg("definite") = false, "Builds the tangent stiffness K at u for multiply().")
        .def(
            "multiply",
            [](const ElasticModel& em, py::handle x_in) {
                if (!em.have_stiffness) throw InvalidArgument("multiply: call build_stiffness(u) first");
                const InArray x = vectors_arg(x_in, "x", em.mesh.num_vertices(), true);
                py::array_t<double> y({py::ssize_t(em.mesh.num_vertices()), py::ssize_t(3)});
                em.op->multiply(x.data(), y.mutable_data());
                return y;
            },
            py::arg("x"), "K x with the K of the last build_stiffness (K = d f / d u).")
        .def(
            "diagonal_blocks",
            [](const ElasticModel& em) {
                if (!em.have_stiffness) throw InvalidArgument("diagonal_blocks: call build_stiffness(u) first");
                py::array_t<double> D({py::ssize_t(em.mesh.num_vertices()), py::ssize_t(3), py::ssize_t(3)});
                em.op->diagonal_blocks(D.mutable_data());
                return D;
            },
            "The 3x3 diagonal blocks of K, shape (#V, 3, 3).")
        .def(
            "inverted_tets",
            [](const ElasticModel& em, py::handle u_in) {
                const InArray u = vectors_arg(u_in, "u", em.mesh.num_vertices(), true);
                return em.op->inverted_tets(u.data());
            },
            py::arg("u"));

    m.def(
        "deformation",
        [](const Mesh& mesh, const std::string& kind, double scale) {
            return new_vectors(deformation_displacement(mesh, parse_deformation(kind), scale));
        },
        py::arg("mesh"), py::arg("kind") = "twist", py::arg("scale") = 1.0,
        "A test displacement: 'twist', 'rotate', 'random' or 'affine' (as the CLI's --deform).");

    // ---- surfaces for rendering (surface.hpp) ----
    m.def(
        "boundary_surface",
        [](const Mesh& mesh) {
            const BoundarySurface b = boundary_surface(mesh);
            py::array_t<std::int32_t> tri({py::ssize_t(b.triangles.size()), py::ssize_t(3)});
            py::array_t<std::int32_t> tet(py::ssize_t(b.tet.size()));
            for (std::size_t k = 0; k < b.triangles.size(); ++k) {
                for (int i = 0; i < 3; ++i) tri.mutable_data()[3 * k + i] = b.triangles[k][i];
                tet.mutable_data()[k] = b.tet[k];
            }
            return py::make_tuple(tri, tet);
        },
        py::arg("mesh"),
        "The mesh's boundary: (triangles (F, 3) wound outward, the tet of each (F,)).");
    m.def(
        "select_surface",
        [](const Mesh& mesh, std::variant<int, std::string> tag, bool outward) {
            const std::vector<int> tags =
                std::holds_alternative<int>(tag) ? std::vector<int>{std::get<int>(tag)} : tags_named(mesh, std::get<std::string>(tag));
            const std::vector<Triangle> t = tagged_triangles(mesh, tags);
            return triangle_array(outward ? orient_outward(mesh, t) : t);
        },
        py::arg("mesh"), py::arg("tag"), py::arg("outward") = true,
        "The mesh file's triangles with a surface tag (int) or Gmsh physical name (str), (F, 3); outward: wound "
        "outward (MeshError for a triangle not on the boundary), else in the file's winding.");
    m.def(
        "surface_load_forces",
        [](const Mesh& mesh, const SurfaceLoad& load) {
            std::vector<double> f(mesh.X.size(), 0.0);
            add_surface_load_forces(mesh.X, load, 1.0, f);
            return new_vectors(f);
        },
        py::arg("mesh"), py::arg("load"), "The load's nodal forces (#V, 3) (N) at full scale.");
    py::class_<Embedding>(m, "Embedding", "Points of a render surface placed in a mesh's tets (embed_points).")
        .def_property_readonly("tet",
                               [](const Embedding& e) {
                                   py::array_t<std::int32_t> a(py::ssize_t(e.tet.size()));
                                   std::copy(e.tet.begin(), e.tet.end(), a.mutable_data());
                                   return a;
                               })
        .def_property_readonly("weight",
                               [](const Embedding& e) {
                                   py::array_t<double> a({py::ssize_t(e.weight.size()), py::ssize_t(4)});
                                   for (std::size_t p = 0; p < e.weight.size(); ++p)
                                       std::copy(e.weight[p].begin(), e.weight[p].end(), a.mutable_data() + 4 * p);
                                   return a;
                               })
        .def_property_readonly("outside", [](const Embedding& e) {
            py::array_t<double> a(py::ssize_t(e.outside.size()));
            std::copy(e.outside.begin(), e.outside.end(), a.mutable_data());
            return a;
        });
    m.def(
        "embed_points",
        [](const Mesh& mesh, py::handle points) {
            const InArray p = vectors_arg(points, "points", -1, true);
            return embed_points(mesh, std::span<const double>(p.data(), std::size_t(p.size())));
        },
        py::arg("mesh"), py::arg("points"),
        "Places points (P, 3) in the mesh's tets (outside the mesh: the nearest tet), once.");
    m.def(
        "embedded_positions",
        [](const Mesh& mesh, const Embedding& e, py::handle u_in) {
            const InArray u = vectors_arg(u_in, "u", mesh.num_vertices(), true);
            std::vector<double> out(3 * e.tet.size());
            embedded_positions<double>(mesh, e, std::span<const double>(u.data(), std::size_t(u.size())), out);
            return new_vectors(out);
        },
        py::arg("mesh"), py::arg("embedding"), py::arg("u"),
        "The embedded points (P, 3) at the displacement u (#V, 3).");
    m.def(
        "vertex_normals",
        [](py::handle triangles, py::handle positions) {
            const InArray x = vectors_arg(positions, "positions", -1, true);
            const std::vector<std::array<index_t, 3>> tri = triangles_arg(triangles, "triangles");
            return new_vectors(vertex_normals(tri, std::span<const double>(x.data(), std::size_t(x.size()))));
        },
        py::arg("triangles"), py::arg("positions"),
        "Area-weighted unit vertex normals (#V, 3) of triangles (F, 3) over positions (#V, 3).");

    // ---- benchmarks ----
    m.def(
        "bench_forces",
        [](const Mesh& mesh, double seconds, ModelKind model, Method method, const Material& material,
           const std::string& backend, int threads) {
            RunOptions run;
            run.backend = backend;
            run.threads = threads;
            run.adaptive = false;  // times the back-end it is given
            run.ordering = "input";
            validate(run);
            ElasticModel em(mesh, Materials(material), model, method, run);
            const std::vector<double> u = deformation_displacement(em.mesh, Deformation::Twist);
            std::vector<double> f(u.size());
            std::vector<double> ns;
            {
                py::gil_scoped_release release;
                ns = time_calls(seconds, [&] { em.op->forces(u.data(), f.data(), false); });
            }
            py::dict r;
            r["tets"] = mesh.num_tets();
            r["calls"] = ns.size();
            r["median_ms"] = median(ns) * 1e-6;
            r["min_ms"] = ns.front() * 1e-6;
            r["median_ns_per_tet"] = median(ns) / mesh.num_tets();
            return r;
        },
        py::arg("mesh"), py::arg("seconds") = 0.5, py::arg("model") = ModelKind::FE, py::arg("method") = Method::Edge,
        py::arg("material") = Material{}, py::arg("backend") = RunOptions{}.backend,
        py::arg("threads") = RunOptions{}.threads,
        "Times the force kernel on the twist configuration (as `edgefem bench --kernel force`).");
    m.def(
        "bench_step",
        [](Sim& sim, double seconds) {
            std::vector<double> ns;
            std::vector<int> its;
            {
                py::gil_scoped_release release;
                ns = time_calls(seconds, [&] { its.push_back(sim.step().solver_iterations); });
            }
            double mean_its = 0;
            for (int i : its) mean_its += i;
            py::dict r;
            r["steps"] = ns.size();
            r["median_ms_per_step"] = median(ns) * 1e-6;
            r["min_ms_per_step"] = ns.front() * 1e-6;
            r["max_ms_per_step"] = ns.back() * 1e-6;
            r["cg_iterations"] = mean_its / double(its.size());
            return r;
        },
        py::arg("simulator"), py::arg("seconds") = 0.5,
        "Times simulator.step() (the state moves on), as `edgefem bench --kernel step`.");
}
