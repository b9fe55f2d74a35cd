// The reference back-end: host memory, the unified vector kernels (CG
// included) as plain serial loops in index order, and the reference
// operator.
#include "edgefem/core/backend.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "reference/serial_launch.hpp"
#include "unified/unified_vector_kernels.hpp"

namespace edgefem {

namespace {

template <class S>
class ReferenceKernels final : public UnifiedVectorKernels<S, SerialLaunch> {
public:
    ReferenceKernels() : UnifiedVectorKernels<S, SerialLaunch>({}) {}
};

template <class S>
class ReferenceBackend final : public Backend<S> {
public:
    const char* name() const override { return "reference"; }
    int threads() const override { return 1; }
    std::unique_ptr<ElasticOperator<S>> make_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method) const override {
        return make_reference_operator<S>(mesh, materials, model, method);
    }
    const VectorKernels<S>& kernels() const override { return kernels_; }
    const VectorMemory& memory() const override { return host_memory(); }

private:
    ReferenceKernels<S> kernels_;
};

}  // namespace

template <class S>
std::shared_ptr<const Backend<S>> make_reference_backend() {
    return std::make_shared<ReferenceBackend<S>>();
}

template std::shared_ptr<const Backend<double>> make_reference_backend();
template std::shared_ptr<const Backend<float>> make_reference_backend();

}  // namespace edgefem
