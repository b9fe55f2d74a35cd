// Numbers in the simulator's error messages.
#pragma once

#include <cstdio>
#include <string>

namespace edgefem::sim {

// %.3e, for residuals in messages (std::to_string prints 0.000000).
inline std::string sci(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", v);
    return buf;
}

// A load fraction with the digits that tell close increments apart.
inline std::string fmt_load(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

}  // namespace edgefem::sim
