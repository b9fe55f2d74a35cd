// What the edgefem subcommands share: mesh loading (files or box:NXxNYxNZ),
// the model/method/precision options, one evaluator interface over the
// edge-based and per-tet kernels, and the text I/O. Every formula lives in
// core/; this only wires it.
#pragma once

#include <concepts>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/executor.hpp"
#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "option_checks.hpp"

namespace edgefem::cli {

// ---- Mesh ---------------------------------------------------------------

struct MeshOptions {
    std::string path;  // file, TetGen prefix or box:NXxNYxNZ
    bool fix_orientation = false;
    bool compact = false;
    std::string ordering = "input";  // input | random | rcm | morton | nd | metis
};

// --ordering NAME into `ordering` (its value on entry is the default).
void add_ordering_option(CLI::App& cmd, std::string& ordering);

struct LoadedMesh {
    // `mesh` is what the kernels run on: renumbered by --ordering when one is
    // given (new_of_old non-empty); `user` then keeps the mesh as read, and
    // vertex data goes in and out in its numbering.
    Mesh user;
    std::vector<index_t> new_of_old;
    Mesh mesh;
    ReadReport read;              // empty for a generated box
    ValidationReport validation;

    const Mesh& user_mesh() const { return new_of_old.empty() ? mesh : user; }
    std::vector<double> to_internal(const std::vector<double>& user_data) const;
    std::vector<double> to_user(const std::vector<double>& internal_data) const;
};

// Adds the MESH positional and --fix-orientation / --compact.
void add_mesh_options(CLI::App& cmd, MeshOptions& opts);

// Reads (or generates) and validates the mesh; throws edgefem::Error.
LoadedMesh load_mesh(const MeshOptions& opts);

// Reader and validation warnings, one "<prefix><text>" line each.
std::vector<std::string> load_warnings(const LoadedMesh& m);

// ---- Model --------------------------------------------------------------

enum class Method { Edge, Tet };
enum class Precision { Double, Float };

struct ModelOptions {
    std::string model = "fe";         // fe | sn
    std::string method = "edge";      // edge | tet
    std::string precision = "double"; // double | float
    std::string layout = "tet-local"; // tet-local | tsep-list (edge FE stiffness)
    Material material;

    ModelKind kind() const { return model == "sn" ? ModelKind::SN : ModelKind::FE; }
    Method method_kind() const { return method == "tet" ? Method::Tet : Method::Edge; }
    Precision precision_kind() const { return precision == "float" ? Precision::Float : Precision::Double; }
    StiffnessLayout layout_kind() const { return parse_stiffness_layout(layout); }
    // Throws InvalidArgument for an invalid material or --method tet --model sn.
    void validate() const;
};

// Throws InvalidArgument when the mesh's size (the largest side of its
// bounding box) lies outside what the kernels of `precision` compute without
// over- or underflow: 1e-30 to 1e30 m in double, 1e-8 to 1e8 m in float. Past
// those, results came out NaN or silently 0 (a mesh scaled by 1e100 gave an
// edge-method energy of exactly 0).
void check_mesh_scale(const Mesh& mesh, Precision precision, const std::string& path);

// Adds --model, --method, --precision, --layout, --young, --poisson, --density.
// `material_required`: --young/--poisson must be given (forces) or default
// to the Material defaults (bench).
void add_model_options(CLI::App& cmd, ModelOptions& opts, bool material_required);

// ---- Execution (parallel back-ends) ----------------------------------------

struct ExecOptions {
    std::string backend = "serial";  // serial | omp | tbb
    int threads = 0;                 // 0: all hardware threads
    std::string variant = "auto";  // auto | colour | gather | atomic | private | owner (docs/parallel.md)
    bool variant_given = false;      // --variant on the command line
    std::string schedule = "dynamic";  // static | dynamic (how the kernels' chunks go to threads)
    // on | off: the loops run serially when their timed first calls were
    // faster so in sum (AdaptiveExecutor); a command sets its default
    // before add_exec_options.
    std::string adaptive = "off";

    // The parallel kernels run unless this is the plain serial default
    // (--backend serial without --variant: core's serial loops).
    bool parallel_kernels() const { return backend != "serial" || variant_given; }
    std::shared_ptr<const Executor> executor() const;
    // "serial" or e.g. "tbb x2, colour".
    std::string describe() const;
};

// With an AdaptiveExecutor: "adaptive: serial|threads (...)", its verdict.
void print_adaptive(const Executor& executor);

// Adds --backend, --threads, --schedule, --adaptive and (with_variant) --variant.
void add_exec_options(CLI::App& cmd, ExecOptions& opts, bool with_variant = true);

// The elastic-model factory a simulator should use under `exec` (empty for
// core's serial kernels with the default layout), running on `executor`.
template <class S>
OperatorFactory<S> operator_factory(const ExecOptions& exec, const std::shared_ptr<const Executor>& executor,
                                    StiffnessLayout layout = StiffnessLayout::TetLocal);

// The kernels `bench` times (see its --help).
enum class Kernel { Force, Stiffness, ForceStiffness, Kx };

// One model (edge FE/SN or per-tet, float or double) behind one interface.
// Inputs and outputs are double; the kernel's precision is used inside, so
// the conversions happen once, outside the timed calls.
class Evaluator {
public:
    virtual ~Evaluator() = default;
    // The configuration as a displacement u = x - X (3 #V).
    virtual void set_displacement(const std::vector<double>& u) = 0;
    // Energy and forces f = dW/du at the current configuration.
    virtual double energy_forces(std::vector<double>& f) = 0;
    // y = K x at the current configuration (builds K).
    virtual void stiffness_times(const std::vector<double>& x, std::vector<double>& y) = 0;

    // Benchmarking: prepare() sets up what `kernel` needs (the force state
    // or a precomputed K, and x for kx) untimed; run() makes one call;
    // consume() keeps the optimiser from dropping the work.
    virtual void prepare(Kernel kernel, const std::vector<double>& x) = 0;
    virtual void run(Kernel kernel) = 0;
    virtual void consume() = 0;
    // The operator's ElasticOperator::forces_from_tet_local_form() and
    // forces_stored_state().
    virtual bool forces_from_tet_local_form() const = 0;
    virtual bool forces_stored_state() const = 0;
};

// Builds the chosen model for `mesh` (opts must be validated) on the chosen
// back-end (evaluator.cpp).
std::unique_ptr<Evaluator> make_evaluator(const Mesh& mesh, const ModelOptions& opts, const ExecOptions& exec);

// ---- Text I/O -------------------------------------------------------------

// Reads one 'x y z' line per vertex (blank lines ignored); throws Error
// naming the file and line on a wrong line count, a non-numeric or a
// non-finite value.
std::vector<double> read_vectors(const std::string& path, index_t count);

// One 'x y z' line per vertex, %.17g each.
void write_vectors(const std::string& path, const std::vector<double>& v);
// One number, %.17g.
void write_scalar(const std::string& path, double value);

// %.<digits>g; 17 digits (the default) round-trip a double exactly.
std::string fmt(double value, int digits = 17);
// Prints "key: value".
void print_kv(const std::string& key, const std::string& value);
void print_kv(const std::string& key, double value);
template <std::integral T>
void print_kv(const std::string& key, T value) {
    print_kv(key, std::to_string(value));
}

// ---- Subcommands (cmd_*.cpp) ----------------------------------------------

// Each adds its subcommand to `app` with a callback that runs it; errors
// propagate as exceptions to main.
void add_info_command(CLI::App& app);
void add_forces_command(CLI::App& app);
void add_bench_command(CLI::App& app);

}  // namespace edgefem::cli
