// Mesh validation: what the kernels need to be true of a mesh, checked once
// with errors that name the file, the line and the element.
#pragma once

#include <string>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem {

struct ValidationOptions {
    // A tet is degenerate when its normalised volume 6*sqrt(2)*|vol| / lmax^3
    // (1 for a regular tet, lmax its longest edge) is below this.
    double degenerate_tolerance = 1e-8;
    // Negatively oriented tets are an error unless this is set; then every
    // such tet gets its last two vertices swapped.
    bool fix_orientation = false;
    // Unreferenced vertices are a warning; with this set they are removed and
    // the tets renumbered.
    bool compact_unreferenced = false;
    // What the messages about inverted tets and unreferenced vertices tell
    // the caller's user to do, in the words of the interface they use (a
    // scene: "set mesh_options.compact"; the CLI: "pass --compact"), so
    // that no message names an option its reader lacks.
    std::string fix_orientation_hint = "set ValidationOptions::fix_orientation";
    std::string compact_hint = "set ValidationOptions::compact_unreferenced";
};

struct ValidationReport {
    index_t flipped_tets = 0;          // tets reoriented (fix_orientation)
    index_t unreferenced_vertices = 0; // vertices no tet uses
    index_t removed_vertices = 0;      // of those, removed (compact_unreferenced)
    std::vector<std::string> warnings;
};

// Throws MeshError on: no tets, index out of range, non-finite coordinates,
// degenerate tets, duplicate tets (same four vertices in any order) and
// negatively oriented tets (unless fix_orientation). Modifies the mesh only
// as the options ask.
ValidationReport validate_mesh(Mesh& mesh, const ValidationOptions& options = {});

// The same checks on a mesh that must not change (Scene::validate, and so
// every Simulator, runs it): negatively oriented tets are an error whatever
// fix_orientation says, unreferenced vertices are left to the caller
// (the Simulator rejects them: a vertex without mass).
void check_mesh(const Mesh& mesh, const ValidationOptions& options = {});

// The checks without which a kernel would read or write outside its arrays:
// array sizes, every index in [0, #V), four distinct vertices per tet.
// MeshError naming the tet. O(#T); every operator factory and write_vtu run
// it, so a mesh that skipped validation fails there with a clear error
// instead of corrupting memory.
void check_mesh_indices(const Mesh& mesh);

}  // namespace edgefem
