// A checkpoint file around the state's bytes (checkpoint.hpp): the header,
// the fingerprint of the simulator that wrote it, the state and the
// checksum. Reading checks each in turn and throws CheckpointError naming
// the file and the first difference.
#pragma once

#include <cstdint>
#include <string>

namespace edgefem::sim {

// What a checkpoint must match to be loaded into a simulator.
struct Fingerprint {
    std::string scalar;      // "double" or "float"
    std::string integrator;  // to_string(Integrator)
    std::string solver;      // "cg/block-jacobi", "cg/amg" or "direct": the state the solver keeps
    std::string numbering;   // the vertex numbering ("" for the mesh's own; OrderedSimulator: its ordering)
    std::uint64_t vertices = 0, tets = 0;
    std::uint64_t mesh_hash = 0;  // rest positions and tets
    std::string backend;     // where it ran (informational: not checked)
};

// The whole file's bytes.
std::string checkpoint_file(const Fingerprint& print, const std::string& state);
// The state's bytes of the file at `path`, after every check.
std::string read_checkpoint_file(const std::string& path, const Fingerprint& expected);

}  // namespace edgefem::sim
