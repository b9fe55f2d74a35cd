#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {
std::string format_mesh_error(const std::string& message, const std::string& file,
                              std::int64_t line) {
    std::string out;
    if (!file.empty()) {
        out.append(file);
        if (line > 0) out.append(":").append(std::to_string(line));
        out.append(": ");
    }
    out += message;
    return out;
}
}  // namespace

MeshError::MeshError(const std::string& message, std::string file, std::int64_t line,
                     std::int64_t element)
    : Error(format_mesh_error(message, file, line)),
      file_(std::move(file)),
      line_(line),
      element_(element),
      reason_(message) {}

}  // namespace edgefem
