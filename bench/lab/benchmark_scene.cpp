#include "lab/benchmark_scene.hpp"

#include <algorithm>
#include <limits>

namespace edgefem {

Scene step_benchmark_scene(Mesh mesh, const Materials& materials) {
    Scene s;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (index_t v = 0; v < mesh.num_vertices(); ++v) {
        lo = std::min(lo, mesh.X[3 * std::size_t(v) + 2]);
        hi = std::max(hi, mesh.X[3 * std::size_t(v) + 2]);
    }
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.X[3 * std::size_t(v) + 2] <= lo + 0.01 * (hi - lo)) s.fixed.push_back(v);
    s.mesh = std::move(mesh);
    s.materials = materials;
    s.gravity = {0, 0, -9.81};
    s.integrator = Integrator::SemiImplicit;
    s.dt = 1e-3;
    s.solver.cg_fixed_iterations = 20;
    s.count_inverted_tets = false;
    return s;
}

}  // namespace edgefem
