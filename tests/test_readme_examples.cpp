// The README's code examples, kept compiling and running.
#include <gtest/gtest.h>

#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/parallel/run_options.hpp"
#include "test_meshes.hpp"

TEST(Readme, KernelExample) {
    using namespace edgefem;
    Mesh mesh = read_mesh(test::test_data_dir() + "/small0.node");
    validate_mesh(mesh);
    auto op = make_cpu_operator<double>(mesh, Materials(Material{1e5, 0.3, 1000}), ModelKind::FE, Method::Edge);
    std::vector<double> u(mesh.X.size(), 0.0), f(u.size()), y(u.size());
    double W = op->forces(u.data(), f.data(), /*energy=*/true);
    op->build_stiffness(/*definite=*/false);
    op->multiply(u.data(), y.data());
    EXPECT_EQ(W, 0.0);
    for (double x : y) EXPECT_EQ(x, 0.0);
}

TEST(Readme, SimulationExample) {
    const edgefem::SceneFile file =
        edgefem::load_scene(edgefem::test::test_data_dir() + "/../../examples/scenes/cantilever.json");
    auto sim = edgefem::make_simulator<double>(file.scene, edgefem::RunOptions{});
    for (int k = 0; k < 100; ++k) {
        sim->external_forces()[3 * 42 + 2] = -0.01;
        const edgefem::StepStats& st = sim->step();
        (void)st;
    }
    std::span<double> u = sim->displacement();
    // The push moved vertex 42 further down than gravity alone does.
    auto free_fall = edgefem::make_simulator<double>(file.scene, edgefem::RunOptions{});
    for (int k = 0; k < 100; ++k) free_fall->step();
    EXPECT_LT(u[3 * 42 + 2], free_fall->displacement()[3 * 42 + 2] - 1e-5);
}
