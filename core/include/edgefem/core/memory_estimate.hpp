// The memory a simulation needs, estimated from the mesh's counts before
// anything is built, and the check that refuses a model that cannot fit:
// a box at the 2^28-tet limit needs about 250 GB, and allocating it got the
// process killed by the system instead of an error.
#pragma once

#include <cstdint>
#include <string>

namespace edgefem {

// Bytes per tet of a Simulator<double> with its topology, coefficients,
// integrator and solver vectors: 880-990 B measured on boxes (issue 27,
// implicit with CG), rounded up.
inline constexpr std::uint64_t kSimulationBytesPerTet = 1000;

// The estimate for `tets` tets (vertices cost far less than the tets they
// belong to and are included in the per-tet figure).
std::uint64_t estimate_simulation_bytes(std::int64_t tets);

// Memory this process can still get: MemAvailable of /proc/meminfo, capped by
// RLIMIT_AS and a cgroup v2 memory.max; 0 when none of them can be read.
std::uint64_t available_memory_bytes();

// Throws InvalidArgument naming `what`, the estimate and what is available
// when the estimate exceeds it. Does nothing below 256 MB, when the
// available memory is unknown, or when the environment variable
// EDGEFEM_NO_MEMORY_CHECK is set to anything but "" or "0" (the CLI's
// --no-memory-check sets it): the estimate can be wrong, so it can be
// overridden.
void check_memory(const std::string& what, std::int64_t tets);

}  // namespace edgefem
