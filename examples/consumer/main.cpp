// A minimal edgefem application: the paper's 1,200-tet box, clamped at its
// x = min end, sagging under gravity for 20 semi-implicit steps.
#include <cmath>
#include <cstdio>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"

int main() {
    edgefem::Scene scene;
    scene.mesh = edgefem::make_box(10, 5, 4);
    scene.materials = edgefem::Material{1e5, 0.3, 1000};
    scene.gravity = {0, 0, -9.81};
    scene.dt = 1e-3;
    for (edgefem::index_t v = 0; v < scene.mesh.num_vertices(); ++v)
        if (scene.mesh.X[3 * v] < -0.0499) scene.fixed.push_back(v);

    edgefem::Simulator<double> sim(std::move(scene));
    for (int k = 0; k < 20; ++k) sim.step();

    double min_uz = 0;
    for (std::size_t i = 2; i < sim.displacement().size(); i += 3)
        min_uz = std::min(min_uz, double(sim.displacement()[i]));
    std::printf("steps: %ld\nmin_uz: %.6g\n", sim.step_index(), min_uz);
    const bool ok = std::isfinite(min_uz) && min_uz < 0;
    std::printf("%s\n", ok ? "edgefem_consumer: ok" : "edgefem_consumer: FAILED");
    return ok ? 0 : 1;
}
