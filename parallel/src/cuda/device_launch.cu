#include "cuda/device_launch.cuh"

namespace edgefem::cuda {

void check(cudaError_t status, const char* what) {
    if (status != cudaSuccess)
        throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
}

__global__ void sum_partials_kernel(int n, const double* partial, double* out) {
    __shared__ double shared[kThreads];
    double s = 0;
    for (int i = threadIdx.x; i < n; i += kThreads) s += partial[i];
    block_tree(shared, s, out);
}

}  // namespace edgefem::cuda
