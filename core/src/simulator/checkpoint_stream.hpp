// The state's part of a checkpoint (checkpoint.hpp): numbers, strings and
// vectors appended to a byte string in the machine's byte order (little-
// endian on every platform edgefem builds for), and read back with every
// length checked. Each part of the simulator that holds state writes and
// reads its own fields (SimState, EnergyGuard, the integrators, the
// solvers), in the same order.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "edgefem/core/backend_vector.hpp"
#include "edgefem/core/checkpoint.hpp"

namespace edgefem::sim {

class CheckpointWriter {
public:
    template <class T>
    void value(const T& x) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes_.append(reinterpret_cast<const char*>(&x), sizeof(T));
    }
    void text(const std::string& s) {
        value(std::uint64_t(s.size()));
        bytes_ += s;
    }
    template <class T>
    void vector(const std::vector<T>& v) {
        value(std::uint64_t(v.size()));
        if (!v.empty()) bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
    // A back-end vector (copied to the host when it lives elsewhere).
    template <class T>
    void vector(const BackendVector<T>& v) {
        std::vector<T> scratch;
        const std::span<const T> h = v.read_host(scratch);
        value(std::uint64_t(h.size()));
        if (!h.empty()) bytes_.append(reinterpret_cast<const char*>(h.data()), h.size() * sizeof(T));
    }
    std::string& bytes() { return bytes_; }

private:
    std::string bytes_;
};

class CheckpointReader {
public:
    // `path` names the file in errors.
    CheckpointReader(std::string_view bytes, std::string path) : bytes_(bytes), path_(std::move(path)) {}

    template <class T>
    T value(const char* what) {
        static_assert(std::is_trivially_copyable_v<T>);
        T x;
        std::memcpy(&x, take(sizeof(T), what), sizeof(T));
        return x;
    }
    std::string text(const char* what) {
        const std::uint64_t n = value<std::uint64_t>(what);
        return std::string(take(n, what), n);
    }
    // `expected`: the length the simulator needs (any when npos).
    template <class T>
    std::vector<T> vector(const char* what, std::size_t expected = std::size_t(-1)) {
        const std::uint64_t n = value<std::uint64_t>(what);
        if (expected != std::size_t(-1) && n != expected) fail(what, std::to_string(n) + " values, expected " + std::to_string(expected));
        if (n > (bytes_.size() - at_) / sizeof(T)) fail(what, "longer than the file");
        std::vector<T> v(n);
        const char* from = take(n * sizeof(T), what);
        if (n > 0) std::memcpy(v.data(), from, n * sizeof(T));  // an empty vector's data() may be null (UBSan)
        return v;
    }
    // Into a back-end vector of its size.
    template <class T>
    void vector(BackendVector<T>& dst, const char* what) {
        const std::vector<T> v = vector<T>(what, dst.size());
        dst.write(v);
    }
    bool done() const { return at_ == bytes_.size(); }
    [[noreturn]] void fail(const char* what, const std::string& why) const {
        throw CheckpointError("checkpoint '" + printable(path_) + "': malformed state (" + what + ": " + why + ")",
                              path_);
    }

private:
    const char* take(std::uint64_t n, const char* what) {
        if (n > bytes_.size() - at_) fail(what, "past the end of the state");
        const char* p = bytes_.data() + at_;
        at_ += n;
        return p;
    }
    std::string_view bytes_;
    std::size_t at_ = 0;
    std::string path_;
};

}  // namespace edgefem::sim
