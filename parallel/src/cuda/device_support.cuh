// What every file of the CUDA back-end uses: error checks that throw
// edgefem::Error naming the call, device arrays (RAII, uploaded from host
// vectors) and the grid of a loop over n items.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem::cuda {

// Throws Error("CUDA: <what>: <CUDA's message>") unless `status` is success.
void check(cudaError_t status, const char* what);
// Checks the last kernel launch (a launch error, not the kernel's end).
inline void check_launch(const char* kernel) { check(cudaGetLastError(), kernel); }

// Threads per block of the element-wise loops.
inline constexpr int kThreads = 256;

// Blocks of a grid-stride loop over n items (capped: each thread then does
// several items; the results never depend on it).
inline unsigned grid_for(std::size_t n) {
    const std::size_t blocks = (n + kThreads - 1) / kThreads;
    return unsigned(blocks < 1 ? 1 : (blocks > 65536 ? 65536 : blocks));
}

// A device allocation of n T's (zeros), freed on destruction.
template <class T>
class DeviceArray {
public:
    DeviceArray() = default;
    explicit DeviceArray(std::size_t n) { resize(n); }
    explicit DeviceArray(const std::vector<T>& host) { assign(host.data(), host.size()); }
    DeviceArray(const DeviceArray&) = delete;
    DeviceArray& operator=(const DeviceArray&) = delete;
    DeviceArray(DeviceArray&& o) noexcept : data_(o.data_), size_(o.size_) {
        o.data_ = nullptr;
        o.size_ = 0;
    }
    DeviceArray& operator=(DeviceArray&& o) noexcept {
        std::swap(data_, o.data_);
        std::swap(size_, o.size_);
        return *this;
    }
    ~DeviceArray() {
        if (data_) cudaFree(data_);
    }
    // n zeros when n differs from size() (else unchanged).
    void resize(std::size_t n) {
        if (n == size_) return;
        if (data_) cudaFree(data_);
        data_ = nullptr;
        size_ = 0;
        if (n == 0) return;
        check(cudaMalloc(reinterpret_cast<void**>(&data_), n * sizeof(T)), "cudaMalloc");
        size_ = n;
        check(cudaMemset(data_, 0, n * sizeof(T)), "cudaMemset");
    }
    void assign(const T* host, std::size_t n) {
        resize(n);
        if (n) check(cudaMemcpy(data_, host, n * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to device");
    }
    std::vector<T> to_host() const {
        std::vector<T> h(size_);
        if (size_) check(cudaMemcpy(h.data(), data_, size_ * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy to host");
        return h;
    }
    T* data() { return data_; }
    const T* data() const { return data_; }
    std::size_t size() const { return size_; }

private:
    T* data_ = nullptr;
    std::size_t size_ = 0;
};

}  // namespace edgefem::cuda
