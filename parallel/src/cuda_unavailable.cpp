// cuda_backend.hpp in a build without the CUDA back-end (no nvcc >= 12 was
// found, or EDGEFEM_CUDA=OFF).
#include "edgefem/parallel/cuda_backend.hpp"

namespace edgefem {

bool cuda_built() { return false; }

std::string cuda_unavailable_reason() {
    return "this build has no CUDA back-end (configure with -DEDGEFEM_CUDA=ON on a machine with nvcc >= 12)";
}

std::string cuda_device_description() { return ""; }

template <class S>
std::shared_ptr<const Backend<S>> make_cuda_backend(const CudaOptions& options) {
    validate(options);
    throw Error("the CUDA back-end cannot run: " + cuda_unavailable_reason());
}

template std::shared_ptr<const Backend<double>> make_cuda_backend<double>(const CudaOptions&);
template std::shared_ptr<const Backend<float>> make_cuda_backend<float>(const CudaOptions&);

}  // namespace edgefem
