// What `edgefem simulate` and `edgefem static` share: loading a scene file
// and writing VTU frames of a simulator's state. Wiring only: the physics
// lives in core (Simulator, the kernels).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "edgefem/core/scene_json.hpp"

namespace edgefem::cli {

// load_scene(path), or the built-in default_scene_file() when `path` is
// empty; prints the scene's warnings to stderr.
SceneFile load_scene_file(const std::string& path);

// Writes SceneFile::file_vertex to `path`: a "# edgefem vertex map" line,
// then one line per output vertex with its 0-based index in the mesh file.
void write_vertex_map(const std::string& path, const std::vector<index_t>& file_vertex);

// Exit codes: 0 ok, 2 bad input (any edgefem::Error but those below),
// 3 a SimulationError, 4 an IoError or filesystem error (main.cpp maps them).
inline constexpr const char* kExitCodesHelp =
    "Exit codes: 0 ok, 2 bad input, 3 simulation failed, 4 a file could not be written.";

void add_simulate_command(CLI::App& app);
void add_static_command(CLI::App& app);

}  // namespace edgefem::cli
