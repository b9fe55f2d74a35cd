// What `edgefem simulate` and `edgefem static` share: loading a scene file
// and writing VTU frames of a simulator's state. Wiring only: the physics
// lives in core (Simulator, the kernels).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/tet_model.hpp"

namespace edgefem::cli {

// load_scene(path), or the built-in default_scene_file() when `path` is
// empty; prints the scene's warnings to stderr.
SceneFile load_scene_file(const std::string& path);

// Writes .vtu frames: displacement, internal forces and (for the FE model)
// the strain energy density of every tet.
class FrameWriter {
public:
    explicit FrameWriter(const Scene& scene);
    void write(const std::string& path, std::span<const double> u, std::span<const double> f);

private:
    const Mesh& mesh_;
    std::optional<TetModel<double>> tets_;  // FE only: the SN energy is not per tet
    std::vector<double> density_;
};

// Exit codes: 0 ok, 2 bad input (any edgefem::Error but a SimulationError),
// 3 a SimulationError (main.cpp maps them).
inline constexpr const char* kExitCodesHelp = "Exit codes: 0 ok, 2 bad input, 3 simulation failed.";

void add_simulate_command(CLI::App& app);
void add_static_command(CLI::App& app);

}  // namespace edgefem::cli
