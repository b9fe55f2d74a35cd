#include "cuda/device_launch.cuh"

namespace edgefem::cuda {

void check(cudaError_t status, const char* what) {
    if (status != cudaSuccess)
        throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}

}  // namespace edgefem::cuda
