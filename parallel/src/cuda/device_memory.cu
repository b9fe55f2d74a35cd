// Device memory for BackendVector: cudaMalloc'd, zero-filled, freed with
// its last owner.
#include "cuda/device_memory.cuh"

namespace edgefem::cuda {

std::shared_ptr<void> DeviceMemory::allocate(std::size_t bytes) const {
    void* p = nullptr;
    check(cudaMalloc(&p, bytes), "cudaMalloc");
    std::shared_ptr<void> owner(p, [](void* q) { cudaFree(q); });
    check(cudaMemset(p, 0, bytes), "cudaMemset");
    return owner;
}

void DeviceMemory::to_host(void* host, const void* data, std::size_t bytes) const {
    check(cudaMemcpy(host, data, bytes, cudaMemcpyDeviceToHost), "cudaMemcpy to host");
}

void DeviceMemory::from_host(void* data, const void* host, std::size_t bytes) const {
    check(cudaMemcpy(data, host, bytes, cudaMemcpyHostToDevice), "cudaMemcpy to device");
}

}  // namespace edgefem::cuda
