// Error types thrown by edgefem. Every error names what went wrong and, where
// it comes from a file, the file, the line and the element.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

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

// A file could not be written (disk full, no permission, a folder in the
// way, ...): not bad input. The message names the file; path() is it.
class IoError : public Error {
public:
    IoError(const std::string& message, std::string path)
        : Error(message), path_(std::move(path)) {}
    const std::string& path() const noexcept { return path_; }

private:
    std::string path_;
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

// Text from input (a path, a key, a token) made safe to echo in a message:
// control characters and other bytes below 0x20 or 0x7f shown as \xHH
// (terminal escape codes never reach a terminal raw), and every run of
// characters without a blank longer than `max_run` cut to its first
// `max_run` characters and "..." (a 100 MB path gives a short message).
std::string printable(std::string_view text, std::size_t max_run = 200);

}  // namespace edgefem
