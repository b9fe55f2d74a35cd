// Scene files: a Scene (and where its output goes) read from JSON. The
// format is documented in docs/scenes.md. Every error names the scene file
// and the key path ("solver.cg_tolerance", "fixed[1].vertices[3]").
#pragma once

#include <string>
#include <vector>

#include "edgefem/core/scene.hpp"

namespace edgefem {

// Where and how often a simulation writes frames; not part of the Scene
// (the library never writes files by itself).
struct OutputSettings {
    std::string dir = "edgefem-out";  // relative to the current directory
    int every = 10;                   // write a frame every this many steps
    bool vtu = true;                  // write .vtu frames and a .pvd series
};

struct SceneFile {
    Scene scene;                        // validated
    OutputSettings output;
    std::string path;                   // the scene file ("" for the built-in default)
    std::vector<std::string> warnings;  // mesh reader/validation notes, unused regions, ...
    // When validation removed vertices (mesh_options.compact, or the extra
    // nodes of higher-order tets): each scene vertex's 0-based index in the
    // mesh file's vertex order, the numbering of the scene's selections.
    // Empty when the scene's numbering is the file's.
    std::vector<index_t> file_vertex;
};

// Reads and parses a scene file; relative paths in it resolve against the
// file's folder. Throws InvalidArgument (bad JSON, unknown key, bad value,
// bad fixed/prescribed file) or MeshError (unreadable or invalid mesh); each
// message starts with the file name and names the key.
SceneFile load_scene(const std::string& path);

// Parses scene text; relative paths resolve against `base_dir` ("" = the
// current directory) and errors start with `source_name`.
SceneFile parse_scene(const std::string& text, const std::string& base_dir,
                      const std::string& source_name);

// The built-in scene `edgefem simulate` runs without a file: a soft beam
// (make_box(40, 10, 8, 0.005): 19,200 tets, 0.2 x 0.05 x 0.04 m; Y = 1e6 Pa,
// nu = 0.3, rho = 1000) clamped at its x = min end and sagging under gravity
// -z, semi-implicit, dt = 1 ms, 1000 steps.
Scene default_scene();
// default_scene() with its output settings (a frame every 20 steps).
SceneFile default_scene_file();

}  // namespace edgefem
