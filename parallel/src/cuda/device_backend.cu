// The CUDA back-end (cuda_backend.hpp): device memory, the vector kernels on
// the device, and the device operators (edge FE / SN, per-tet).
#include "cuda/device_memory.cuh"
#include "cuda/device_operators.cuh"
#include "cuda/device_vector_kernels.cuh"
#include "edgefem/parallel/cuda_backend.hpp"

namespace edgefem {

bool cuda_built() { return true; }

std::string cuda_unavailable_reason() {
    int count = 0;
    const cudaError_t status = cudaGetDeviceCount(&count);
    if (status != cudaSuccess) {
        cudaGetLastError();  // clear it
        return std::string("no usable CUDA device (") + cudaGetErrorString(status) + ")";
    }
    if (count == 0) return "no CUDA device is visible";
    return "";
}

std::string cuda_device_description() {
    if (!cuda_unavailable_reason().empty()) return "";
    int device = 0, driver = 0, runtime = 0;
    cudaGetDevice(&device);
    cudaDeviceProp prop{};
    cudaGetDeviceProperties(&prop, device);
    cudaDriverGetVersion(&driver);
    cudaRuntimeGetVersion(&runtime);
    const auto version = [](int v) { return std::to_string(v / 1000) + "." + std::to_string(v % 1000 / 10); };
    return std::string(prop.name) + " (sm_" + std::to_string(prop.major) + std::to_string(prop.minor) + ", " +
           std::to_string(prop.totalGlobalMem >> 20) + " MiB, driver " + version(driver) + ", runtime " +
           version(runtime) + ")";
}

namespace {

template <class S>
class DeviceBackend final : public Backend<S> {
public:
    explicit DeviceBackend(const CudaOptions& options) : options_(options) {}
    const char* name() const override { return "cuda"; }
    int threads() const override { return 1; }
    std::unique_ptr<ElasticOperator<S>> make_operator(const Mesh& mesh, const Materials& materials, ModelKind model,
                                                      Method method) const override {
        if (method == Method::Tet) {
            if (model == ModelKind::SN)
                throw InvalidArgument("the spring-network model exists only for the edge method");
            return cuda::make_device_tet_operator<S>(mesh, materials);
        }
        return cuda::make_device_edge_operator<S>(mesh, materials, model, options_.multiply_lanes);
    }
    const VectorKernels<S>& kernels() const override { return kernels_; }
    const VectorMemory& memory() const override { return memory_; }

private:
    CudaOptions options_;
    cuda::DeviceMemory memory_;
    cuda::DeviceVectorKernels<S> kernels_;
};

}  // namespace

template <class S>
std::shared_ptr<const Backend<S>> make_cuda_backend(const CudaOptions& options) {
    validate(options);
    const std::string why = cuda_unavailable_reason();
    if (!why.empty()) throw Error("the CUDA back-end cannot run: " + why);
    return std::make_shared<DeviceBackend<S>>(options);
}

template std::shared_ptr<const Backend<double>> make_cuda_backend<double>(const CudaOptions&);
template std::shared_ptr<const Backend<float>> make_cuda_backend<float>(const CudaOptions&);

}  // namespace edgefem
