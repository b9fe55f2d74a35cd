#include "edgefem/core/memory_estimate.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {

// "MemAvailable:   123456 kB" from /proc/meminfo, in bytes; 0 if absent.
std::uint64_t meminfo_available() {
    std::ifstream in("/proc/meminfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("MemAvailable:", 0) == 0) {
            std::istringstream fields(line.substr(13));
            std::uint64_t kb = 0;
            if (fields >> kb) return kb * 1024;
        }
    return 0;
}

// A cgroup v2 limit on this process ("max": none); 0 if none or unreadable.
std::uint64_t cgroup_limit() {
    std::ifstream in("/sys/fs/cgroup/memory.max");
    std::string value;
    if (!(in >> value) || value == "max") return 0;
    char* end = nullptr;
    const unsigned long long v = std::strtoull(value.c_str(), &end, 10);
    return (end && *end == '\0') ? v : 0;
}

std::string gigabytes(std::uint64_t bytes) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g GB", static_cast<double>(bytes) / 1e9);
    return buf;
}

}  // namespace

std::uint64_t estimate_simulation_bytes(std::int64_t tets) {
    return tets > 0 ? static_cast<std::uint64_t>(tets) * kSimulationBytesPerTet : 0;
}

std::uint64_t available_memory_bytes() {
    std::uint64_t available = meminfo_available();
    const auto cap = [&](std::uint64_t limit) {
        if (limit > 0) available = available == 0 ? limit : std::min(available, limit);
    };
    rlimit as{};
    if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) cap(as.rlim_cur);
    cap(cgroup_limit());
    return available;
}

void check_memory(const std::string& what, std::int64_t tets) {
    const char* off = std::getenv("EDGEFEM_NO_MEMORY_CHECK");
    if (off && *off && std::strcmp(off, "0") != 0) return;
    const std::uint64_t need = estimate_simulation_bytes(tets);
    if (need < (std::uint64_t(1) << 28)) return;
    const std::uint64_t available = available_memory_bytes();
    if (available == 0 || need <= available) return;
    throw InvalidArgument(what + ": " + std::to_string(tets) + " tets need about " + gigabytes(need) +
                          " to simulate (estimated at " + std::to_string(kSimulationBytesPerTet) +
                          " bytes per tet) but about " + gigabytes(available) +
                          " are available; use a smaller mesh, or set EDGEFEM_NO_MEMORY_CHECK=1 "
                          "(edgefem --no-memory-check) to try anyway");
}

}  // namespace edgefem
