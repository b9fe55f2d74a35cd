// `edgefem info MESH`: sizes, regions, the boundary, model memory and shape
// statistics of a mesh.
#include <chrono>
#include <map>
#include <memory>

#include "common.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/core/mesh_quality.hpp"
#include "edgefem/core/surface.hpp"
#include "edgefem/core/tet_model.hpp"
#include "edgefem/core/topology.hpp"

namespace edgefem::cli {

namespace {

void run_info(const MeshOptions& opts) {
    const LoadedMesh lm = load_mesh(opts);
    const Mesh& mesh = lm.mesh;
    // Volumes and dihedral angles under- or overflow past it (0 degrees).
    check_mesh_scale(mesh, Precision::Double, opts.path);

    const auto t0 = std::chrono::steady_clock::now();
    const Topology topo = build_topology(mesh);
    const auto t1 = std::chrono::steady_clock::now();

    // Model sizes do not depend on the material values: the defaults do.
    const Material material;
    const EdgeModel<double> edge = make_edge_model<double>(topo, compute_coefficients(mesh, topo, material));
    const TetModel<double> tet = make_tet_model<double>(mesh, material);
    const MeshQuality q = mesh_quality(mesh);

    print_kv("mesh", opts.path);
    print_kv("vertices", mesh.num_vertices());
    print_kv("tets", mesh.num_tets());
    print_kv("edges", topo.num_edges());
    print_kv("tseps", topo.num_tseps());
    print_kv("tseps_vertex_sharing", topo.num_tseps() - topo.num_opposite_tseps());
    print_kv("tseps_opposite", topo.num_opposite_tseps());
    print_kv("boundary_triangles", boundary_surface(mesh).triangles.size());
    std::map<int, long> region_tets;
    for (index_t t = 0; t < mesh.num_tets(); ++t) ++region_tets[mesh.tet_region(t)];
    print_kv("regions", region_tets.size());
    for (const auto& [r, n] : region_tets) print_kv("region " + std::to_string(r), std::to_string(n) + " tets");
    print_kv("bytes_per_tet", fmt(edge.bytes_per_tet(true), 6));
    print_kv("bytes_per_tet_force_only", fmt(edge.bytes_per_tet(false), 6));
    print_kv("bytes_per_tet_per_tet_method", fmt(tet.bytes_per_tet(), 6));
    print_kv("min_volume", fmt(q.min_volume, 6));
    print_kv("max_volume", fmt(q.max_volume, 6));
    print_kv("total_volume", fmt(q.total_volume, 6));
    print_kv("min_dihedral_deg", fmt(q.min_dihedral_deg, 6));
    print_kv("max_dihedral_deg", fmt(q.max_dihedral_deg, 6));
    print_kv("bbox", fmt(q.bbox_min[0], 6) + " " + fmt(q.bbox_min[1], 6) + " " + fmt(q.bbox_min[2], 6) + " " +
                         fmt(q.bbox_max[0], 6) + " " + fmt(q.bbox_max[1], 6) + " " + fmt(q.bbox_max[2], 6));
    print_kv("skipped_elements", lm.read.skipped_elements);
    if (!lm.read.skipped_summary.empty()) print_kv("skipped", lm.read.skipped_summary);
    print_kv("flipped_tets", lm.validation.flipped_tets);
    print_kv("unreferenced_vertices", lm.validation.unreferenced_vertices);
    print_kv("removed_vertices", lm.validation.removed_vertices);
    const auto warnings = load_warnings(lm);
    print_kv("warnings", warnings.size());
    for (const auto& w : warnings) print_kv("warning", w);
    print_kv("topology_ms", fmt(std::chrono::duration<double, std::milli>(t1 - t0).count(), 4));
}

}  // namespace

void add_info_command(CLI::App& app) {
    auto opts = std::make_shared<MeshOptions>();
    opts->ordering = "input";  // describes the mesh as given unless --ordering asks otherwise
    auto* cmd = app.add_subcommand("info", "Print mesh sizes, edge/TSEP counts, model memory and shape statistics");
    add_mesh_options(*cmd, *opts);
    cmd->callback([opts] { run_info(*opts); });
}

}  // namespace edgefem::cli
