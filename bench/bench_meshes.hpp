// Benchmark meshes: ../shared/meshes when present ($EDGEFEM_MESH_DIR
// overrides), generated boxes of the same size otherwise. Loaded once each.
// "NAME@rcm": the mesh renumbered by reverse Cuthill-McKee (the ordering
// the library recommends for large meshes, docs/layouts.md).
#pragma once

#include <cstdio>
#include <map>
#include <string>

#include "lab/named_mesh.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

namespace edgefem::bench {

inline const Mesh& bench_mesh(const std::string& name) {
    static std::map<std::string, Mesh> cache;
    auto it = cache.find(name);
    if (it == cache.end()) {
        const std::string rcm = "@rcm";
        if (name.size() > rcm.size() && name.compare(name.size() - rcm.size(), rcm.size(), rcm) == 0) {
            const Mesh& base = bench_mesh(name.substr(0, name.size() - rcm.size()));
            return cache.emplace(name, permute_mesh(base, vertex_ordering(base, Ordering::RCM))).first->second;
        }
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
