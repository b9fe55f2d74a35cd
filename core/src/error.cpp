#include "edgefem/core/error.hpp"

#include <algorithm>

namespace edgefem {

namespace {
std::string format_mesh_error(const std::string& message, const std::string& file,
                              std::int64_t line) {
    std::string out;
    if (!file.empty()) {
        out.append(printable(file));
        if (line > 0) out.append(":").append(std::to_string(line));
        out.append(": ");
    }
    out += message;
    return out;
}
}  // namespace

std::string printable(std::string_view text, std::size_t max_run) {
    std::string out;
    out.reserve(std::min<std::size_t>(text.size(), 4096));
    std::size_t run = 0;     // characters of the current run written
    bool cut = false;        // the current run was cut
    for (const char c : text) {
        const auto u = static_cast<unsigned char>(c);
        if (c == ' ' || c == '\n' || c == '\t') {
            run = 0;
            cut = false;
            out += c == '\t' ? ' ' : c;
            continue;
        }
        if (cut) continue;
        if (run == max_run) {
            out += "...";
            cut = true;
            continue;
        }
        ++run;
        if (u < 0x20 || u == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            out += "\\x";
            out += hex[u >> 4];
            out += hex[u & 15];
        } else {
            out += c;
        }
    }
    return out;
}

MeshError::MeshError(const std::string& message, std::string file, std::int64_t line,
                     std::int64_t element)
    : Error(format_mesh_error(message, file, line)),
      file_(std::move(file)),
      line_(line),
      element_(element),
      reason_(message) {}

}  // namespace edgefem
