// Error types thrown by edgefem. Every error names what went wrong and, where
// it comes from a file, the file, the line and the element.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace edgefem {

// Base class of every exception edgefem throws on bad input or failure.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Invalid arguments or parameters (nonsense material, size mismatch, ...).
class InvalidArgument : public Error {
public:
    using Error::Error;
};

// A problem with a mesh: unreadable or malformed file, or a mesh that fails
// validation. `file` is empty and `line` is 0 when unknown; `element` is -1
// when the problem is not tied to one element.
class MeshError : public Error {
public:
    MeshError(const std::string& message, std::string file = {}, std::int64_t line = 0,
              std::int64_t element = -1);
    const std::string& file() const noexcept { return file_; }
    std::int64_t line() const noexcept { return line_; }
    std::int64_t element() const noexcept { return element_; }
    // The message without the "file:line: " prefix.
    const std::string& reason() const noexcept { return reason_; }

private:
    std::string file_;
    std::int64_t line_;
    std::int64_t element_;
    std::string reason_;
};

}  // namespace edgefem
