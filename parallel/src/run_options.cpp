#include "edgefem/parallel/run_options.hpp"

#include "edgefem/core/error.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "edgefem/parallel/adaptive_executor.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/parallel/cuda_backend.hpp"
#include "edgefem/parallel/executors.hpp"

namespace edgefem {

namespace {

// parse(value), its InvalidArgument prefixed with the option's name.
template <class Parse>
void check_option(const char* option, const std::string& value, Parse&& parse) {
    try {
        parse(value);
    } catch (const InvalidArgument& e) {
        throw InvalidArgument(std::string("run option ") + option + ": " + e.what());
    }
}

bool uses_executor(const RunOptions& run) {
    return run.backend != "reference" && run.backend != "cuda" && !(run.backend == "serial" && run.variant == "auto");
}

}  // namespace

void validate(const RunOptions& run) {
    // auto, reference and cuda, then the executors' kinds.
    if (run.backend != "auto" && run.backend != "reference" && run.backend != "cuda")
        check_option("backend", run.backend, [](const std::string& b) {
            try {
                parse_executor_kind(b);
            } catch (const InvalidArgument&) {
                throw InvalidArgument("unknown value '" + b + "' (expected auto, reference, serial, omp, tbb, pool or cuda)");
            }
        });
    if (run.threads < 0 || run.threads > kMaxThreads)
        throw InvalidArgument("run option threads: " + std::to_string(run.threads) + " is outside 0.." +
                              std::to_string(kMaxThreads) + " (0: every hardware thread)");
    check_option("variant", run.variant, [](const std::string& v) { parse_variant(v); });
    check_option("schedule", run.schedule, [](const std::string& v) { parse_schedule(v); });
    check_option("ordering", run.ordering, [](const std::string& v) { parse_ordering(v); });
    check_option("layout", run.layout, [](const std::string& v) { parse_stiffness_layout(v); });
    if ((run.backend == "reference" || run.backend == "cuda") && run.variant != "auto")
        throw InvalidArgument("run option variant: '" + run.variant + "' applies to the CPU back-end; the " +
                              run.backend + " back-end has none");
}

std::shared_ptr<const Executor> make_run_executor(const RunOptions& run) {
    validate(run);
    if (!uses_executor(run)) return nullptr;
    const int threads = run.threads > 0 ? run.threads : hardware_threads();
    if (run.backend == "auto" && threads == 1 && run.variant == "auto") return nullptr;  // the serial loops
    const ExecutorKind kind = run.backend != "auto" ? parse_executor_kind(run.backend)
                              : threads == 1        ? ExecutorKind::Serial
                                                    : ExecutorKind::Pool;
    auto ex = make_executor(kind, kind == ExecutorKind::Serial ? 1 : threads, parse_schedule(run.schedule));
    return run.adaptive && ex->threads() > 1 ? make_adaptive(std::move(ex)) : ex;
}

template <class S>
OperatorFactory<S> make_run_factory(const RunOptions& run, std::shared_ptr<const Executor> executor) {
    validate(run);
    if (run.backend == "cuda")
        throw InvalidArgument("run option backend: cuda runs whole simulations (make_run_backend, make_simulator); "
                              "its operators work on device vectors, not on host arrays");
    if (run.backend == "reference")
        return [](const Mesh& mesh, const Materials& materials, ModelKind model, Method method) {
            return make_reference_operator<S>(mesh, materials, model, method);
        };
    return cpu_operator_factory<S>({std::move(executor), parse_variant(run.variant), parse_stiffness_layout(run.layout)});
}

template <class S>
std::shared_ptr<const Backend<S>> make_run_backend(const RunOptions& run, std::shared_ptr<const Executor> executor) {
    validate(run);
    if (run.backend == "cuda") return make_cuda_backend<S>();
    auto factory = make_run_factory<S>(run, executor);
    return make_cpu_backend<S>(std::move(executor), std::move(factory));
}

template <class S>
std::unique_ptr<OrderedSimulator<S>> make_simulator(const Scene& scene, const RunOptions& run) {
    auto ex = make_run_executor(run);
    return std::make_unique<OrderedSimulator<S>>(scene, parse_ordering(run.ordering), make_run_backend<S>(run, ex));
}

std::string describe(const RunOptions& run, const Executor* executor) {
    if (run.backend == "reference") return "reference";
    if (run.backend == "cuda") return "cuda (" + cuda_device_description() + ")";
    if (!executor) return "serial";
    std::string name = executor->name();
    if (const auto* a = dynamic_cast<const AdaptiveExecutor*>(executor)) name = a->inner().name();
    return name + " x" + std::to_string(executor->threads()) + ", " + run.variant + ", " + run.schedule +
           (run.adaptive && executor->threads() > 1 ? ", adaptive" : "");
}

template OperatorFactory<double> make_run_factory<double>(const RunOptions&, std::shared_ptr<const Executor>);
template OperatorFactory<float> make_run_factory<float>(const RunOptions&, std::shared_ptr<const Executor>);
template std::shared_ptr<const Backend<double>> make_run_backend<double>(const RunOptions&,
                                                                           std::shared_ptr<const Executor>);
template std::shared_ptr<const Backend<float>> make_run_backend<float>(const RunOptions&, std::shared_ptr<const Executor>);
template std::unique_ptr<OrderedSimulator<double>> make_simulator<double>(const Scene&, const RunOptions&);
template std::unique_ptr<OrderedSimulator<float>> make_simulator<float>(const Scene&, const RunOptions&);

}  // namespace edgefem
