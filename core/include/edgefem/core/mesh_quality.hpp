// Shape statistics of a mesh, as `edgefem info` prints them.
#pragma once

#include "edgefem/core/mesh.hpp"

namespace edgefem {

struct MeshQuality {
    double min_volume = 0, max_volume = 0, total_volume = 0;  // signed rest volumes (m^3)
    double min_dihedral_deg = 0, max_dihedral_deg = 0;        // over all tets' 6 dihedral angles
    double bbox_min[3] = {0, 0, 0}, bbox_max[3] = {0, 0, 0};
};

MeshQuality mesh_quality(const Mesh& mesh);

}  // namespace edgefem
