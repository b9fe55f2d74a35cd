// Benchmark meshes: ../shared/meshes when present ($EDGEFEM_MESH_DIR
// overrides), generated boxes of the same size otherwise. Loaded once each.
#pragma once

#include <cstdio>
#include <map>
#include <string>

#include "edgefem/core/named_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"

namespace edgefem::bench {

inline const Mesh& bench_mesh(const std::string& name) {
    static std::map<std::string, Mesh> cache;
    auto it = cache.find(name);
    if (it == cache.end()) {
        std::string origin;
        Mesh mesh = load_named_mesh(mesh_dir(EDGEFEM_SHARED_MESHES), name, &origin);
        validate_mesh(mesh);
        std::fprintf(stderr, "mesh %s: %s (%d tets)\n", name.c_str(), origin.c_str(), mesh.num_tets());
        it = cache.emplace(name, std::move(mesh)).first;
    }
    return it->second;
}

inline const char* const kBenchMeshes[] = {"box-1200", "bunny-4k", "armadillo-7k", "bunny-250k", "bunny-1m"};

}  // namespace edgefem::bench
