// Where `edgefem simulate` and `edgefem static` may write (docs/scenes.md,
// "Output paths"): a scene's output.dir stays under the current folder
// unless --out names another; a symbolic link at an output file's name is
// never followed; a file is replaced only when it is one edgefem wrote (a
// frame or series of an earlier run). Files themselves are written through
// OutputFile (whole or not at all).
#pragma once

#include <string>
#include <string_view>

#include "edgefem/core/scene_json.hpp"

namespace edgefem::cli {

// A scene's output.dir: throws InvalidArgument naming the scene when it is
// absolute or leads outside the current folder (after resolving "..", and
// symbolic links of the part that exists).
void check_scene_output_dir(const std::string& dir, const std::string& scene);

// Creates `dir` (and its parents); throws InvalidArgument naming `option`
// when it exists and is not a folder, IoError when it cannot be created.
void make_output_dir(const std::string& dir, const std::string& option);

// Throws IoError unless `path` is absent, or a regular file (not a symbolic
// link) whose text starts with `signature` ("" accepts any regular file).
void check_replaceable(const std::string& path, std::string_view signature);

// The first bytes of what write_vtu and PvdSeries write.
inline constexpr std::string_view kVtuSignature = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\"";
inline constexpr std::string_view kPvdSignature = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\"";
inline constexpr std::string_view kVertexMapSignature = "# edgefem vertex map";
// And the checkpoints' magic (edgefem/core/checkpoint.hpp).
inline constexpr std::string_view kCheckpointSignature = "EFEMCKPT";
// ... and what write_ply and write_obj write.
inline constexpr std::string_view kPlySignature = "ply\nformat binary_little_endian 1.0\ncomment edgefem surface\n";
inline constexpr std::string_view kObjSignature = "# edgefem surface";

// The signature of a frame in `format`.
inline std::string_view frame_signature(OutputFormat format) {
    return format == OutputFormat::Ply ? kPlySignature : format == OutputFormat::Obj ? kObjSignature : kVtuSignature;
}

}  // namespace edgefem::cli
