// Checkpoint files: a Simulator's whole state written to disk and read back
// so that a run continues bit for bit as if it had not stopped (on the same
// back-end). Simulator::save_checkpoint and load_checkpoint (simulator.hpp)
// write and read them; the format is in docs/api.md, "Checkpoints".
//
// A file is a header (magic, format version, file length), the fingerprint
// of the simulator that wrote it (scalar type, integrator, linear solver and
// preconditioner, vertex numbering, vertex and tet counts, a hash of the
// rest positions and the tets), the state, and a 64-bit FNV-1a checksum of
// everything before it. Loading checks them in that order: a file that is
// not a checkpoint, truncated, corrupt or written for another simulator is
// a CheckpointError naming the file and what differs, and the simulator is
// left as it was.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "edgefem/core/error.hpp"
#include "edgefem/core/mesh.hpp"

namespace edgefem {

// A checkpoint that cannot be read, or not into this simulator. path() is
// the file. (A checkpoint that cannot be written is an IoError.)
class CheckpointError : public Error {
public:
    CheckpointError(const std::string& message, std::string path) : Error(message), path_(std::move(path)) {}
    const std::string& path() const noexcept { return path_; }

private:
    std::string path_;
};

// The format version this build writes and reads.
inline constexpr std::uint32_t kCheckpointVersion = 6;

// The 64-bit FNV-1a hash of `bytes` continuing from `hash` (the file's
// checksum and the mesh hash).
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t hash = 0xcbf29ce484222325ull);

// The hash of a mesh's rest positions and tets (the fingerprint's).
std::uint64_t mesh_hash(const Mesh& mesh);

}  // namespace edgefem
