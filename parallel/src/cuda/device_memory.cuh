#pragma once

#include "cuda/device_support.cuh"
#include "edgefem/core/backend_vector.hpp"

namespace edgefem::cuda {

class DeviceMemory final : public VectorMemory {
public:
    MemorySpace space() const override { return MemorySpace::Device; }
    std::shared_ptr<void> allocate(std::size_t bytes) const override;
    void to_host(void* host, const void* data, std::size_t bytes) const override;
    void from_host(void* data, const void* host, std::size_t bytes) const override;
};

}  // namespace edgefem::cuda
