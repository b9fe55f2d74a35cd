// The CPU back-end: host memory, the unified vector kernels on fixed blocks
// of an Executor, and CG in its fused form (cg.hpp's conjugate_gradient:
// one parallel region of three phases per iteration).
#include "cpu/blocked_launch.hpp"
#include "edgefem/core/backend.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "unified/unified_vector_kernels.hpp"

namespace edgefem {

namespace {

template <class S>
class CpuKernels final : public UnifiedVectorKernels<S, BlockedLaunch> {
public:
    explicit CpuKernels(std::shared_ptr<const Executor> ex) : UnifiedVectorKernels<S, BlockedLaunch>({std::move(ex)}) {}

    CgResult cg(CgSystem& A, const CgPreconditioner& M, const std::uint8_t* free_dof, const double* b, double* x,
                std::size_t n, const CgSettings& settings, CgWork& work) const override {
        return conjugate_gradient(
            *this->launch_.ex, n, free_dof, [&](const double* in, double* out) { A.products(in, out); },
            [&](std::size_t lo, std::size_t hi, const double* in, double* out) { A.finish(lo, hi, in, out); },
            [&](std::size_t lo, std::size_t hi, const double* r, double* z) { M.apply(lo, hi, r, z); }, b, x,
            settings.tolerance, settings.max_iterations, settings.fixed_iterations, work, M.whole_vector());
    }
};

template <class S>
class CpuBackend final : public Backend<S> {
public:
    CpuBackend(std::shared_ptr<const Executor> ex, OperatorFactory<S> factory)
        : ex_(std::move(ex)), factory_(std::move(factory)), kernels_(ex_) {}
    const char* name() const override { return ex_->name(); }
    int threads() const override { return ex_->threads(); }
    std::unique_ptr<ElasticOperator<S>> make_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method) const override {
        if (factory_) return factory_(mesh, materials, model, method);
        return make_reference_operator<S>(mesh, materials, model, method);
    }
    const VectorKernels<S>& kernels() const override { return kernels_; }
    const VectorMemory& memory() const override { return host_memory(); }
    std::shared_ptr<const Executor> executor() const override { return ex_; }

private:
    std::shared_ptr<const Executor> ex_;
    OperatorFactory<S> factory_;
    CpuKernels<S> kernels_;
};

}  // namespace

template <class S>
std::shared_ptr<const Backend<S>> make_cpu_backend(std::shared_ptr<const Executor> executor,
                                                          OperatorFactory<S> factory) {
    if (!executor) executor = std::make_shared<SerialExecutor>();
    return std::make_shared<CpuBackend<S>>(std::move(executor), std::move(factory));
}

template std::shared_ptr<const Backend<double>> make_cpu_backend(std::shared_ptr<const Executor>,
                                                                        OperatorFactory<double>);
template std::shared_ptr<const Backend<float>> make_cpu_backend(std::shared_ptr<const Executor>,
                                                                       OperatorFactory<float>);

}  // namespace edgefem
