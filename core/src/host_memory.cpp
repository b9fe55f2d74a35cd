#include <cstring>
#include <new>

#include "edgefem/core/backend_vector.hpp"

namespace edgefem {

namespace {

class HostMemory final : public VectorMemory {
public:
    MemorySpace space() const override { return MemorySpace::Host; }
    std::shared_ptr<void> allocate(std::size_t bytes) const override {
        constexpr std::align_val_t align{64};
        void* p = ::operator new(bytes, align);
        std::memset(p, 0, bytes);
        return std::shared_ptr<void>(p, [](void* q) { ::operator delete(q, align); });
    }
    void to_host(void* host, const void* data, std::size_t bytes) const override { std::memcpy(host, data, bytes); }
    void from_host(void* data, const void* host, std::size_t bytes) const override { std::memcpy(data, host, bytes); }
};

}  // namespace

const VectorMemory& host_memory() {
    static const HostMemory memory;
    return memory;
}

}  // namespace edgefem
