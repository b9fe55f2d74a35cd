// Vectors in a back-end's memory: a pointer, a size and an owner that frees
// the memory, allocated through the back-end's VectorMemory. The back-end's
// kernels work on data(); the host reads and writes the elements through
// host() (host memory only, zero-copy) or read() / write() (any memory).
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"

namespace edgefem {

enum class MemorySpace { Host, Device };

// A back-end's memory: zero-filled allocations, and copies to and from
// host memory.
class VectorMemory {
public:
    virtual ~VectorMemory() = default;
    virtual MemorySpace space() const = 0;
    // `bytes` of zeros; freed when the last copy of the owner goes.
    virtual std::shared_ptr<void> allocate(std::size_t bytes) const = 0;
    virtual void to_host(void* host, const void* data, std::size_t bytes) const = 0;
    virtual void from_host(void* data, const void* host, std::size_t bytes) const = 0;
};

// Host memory, 64-byte aligned: what CPU back-ends allocate.
const VectorMemory& host_memory();

template <class T>
class BackendVector {
public:
    // Empty, in host memory.
    BackendVector() = default;
    // n zeros in `memory` (which must outlive the vector).
    BackendVector(const VectorMemory& memory, std::size_t n) : memory_(&memory) { resize(n); }
    BackendVector(BackendVector&&) noexcept = default;
    BackendVector& operator=(BackendVector&&) noexcept = default;
    BackendVector(const BackendVector&) = delete;  // copies go through the back-end's kernels
    BackendVector& operator=(const BackendVector&) = delete;

    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    T* data() { return data_; }
    const T* data() const { return data_; }
    const VectorMemory& memory() const { return *memory_; }

    // n zeros when n differs from size(); else unchanged.
    void resize(std::size_t n) {
        if (n == size_) return;
        owner_ = n ? memory_->allocate(n * sizeof(T)) : nullptr;
        data_ = static_cast<T*>(owner_.get());
        size_ = n;
    }

    // The elements themselves; Error unless the memory is host memory.
    std::span<T> host() {
        require_host();
        return {data_, size_};
    }
    std::span<const T> host() const {
        require_host();
        return {data_, size_};
    }
    // Copies of all elements, in any memory.
    void read(std::span<T> out) const {
        check_size(out.size());
        if (size_) memory_->to_host(out.data(), data_, size_ * sizeof(T));
    }
    void write(std::span<const T> in) {
        check_size(in.size());
        if (size_) memory_->from_host(data_, in.data(), size_ * sizeof(T));
    }
    // The elements on the host: host() for host memory, else a copy in
    // `scratch`.
    std::span<const T> read_host(std::vector<T>& scratch) const {
        if (memory_->space() == MemorySpace::Host) return {data_, size_};
        scratch.resize(size_);
        read(scratch);
        return scratch;
    }

private:
    void require_host() const {
        if (memory_->space() != MemorySpace::Host)
            throw Error("BackendVector: host access to device memory (copy with read() / write())");
    }
    void check_size(std::size_t n) const {
        if (n != size_)
            throw InvalidArgument("BackendVector: " + std::to_string(n) + " values for a vector of " +
                                  std::to_string(size_));
    }

    const VectorMemory* memory_ = &host_memory();
    std::shared_ptr<void> owner_;
    T* data_ = nullptr;
    std::size_t size_ = 0;
};

}  // namespace edgefem
