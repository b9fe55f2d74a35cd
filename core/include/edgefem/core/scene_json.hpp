// Scene files: a Scene (and where its output goes) read from JSON. The
// format is documented in docs/scenes.md. Every error names the scene file
// and the key path ("solver.cg_tolerance", "fixed[1].vertices[3]").
#pragma once

#include <string>
#include <vector>

#include "edgefem/core/scene.hpp"

namespace edgefem {

// Which fields the frames carry (docs/scenes.md, "Output of edgefem
// simulate"); the strain and stress fields need the FE model.
struct OutputFields {
    bool displacement = true, velocity = true, force = true;            // point
    bool energy_density = true, green_strain = false, pk2_stress = false, von_mises = true;  // cell
};

// What a frame holds: the tet mesh or its boundary surface.
enum class OutputMesh { Volume, Surface };
// The frames' file format: VTU (compressed binary or ASCII), PLY (binary
// little endian) or OBJ; PLY and OBJ only for the surface.
enum class OutputFormat { Binary, Ascii, Ply, Obj };

// Where and how often a simulation writes frames; not part of the Scene
// (the library never writes files by itself).
struct OutputSettings {
    std::string dir = "edgefem-out";  // relative to the current directory
    int every = 10;                   // write a frame every this many steps
    bool vtu = true;                  // write frames (and, for VTU, a .pvd series)
    OutputFormat format = OutputFormat::Binary;
    OutputMesh mesh = OutputMesh::Volume;
    OutputFields fields;
};

// The names of output.format's values ("binary", "ascii", "ply", "obj") and
// the frames' file extension (".vtu", ".ply", ".obj").
const char* to_string(OutputFormat format);
const char* file_extension(OutputFormat format);
// The OutputFormat called `name`; InvalidArgument naming `what` and the
// valid names otherwise. Also checks that PLY and OBJ go with a surface
// (naming `what` again).
OutputFormat parse_output_format(const std::string& name, OutputMesh mesh, const std::string& what);

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
