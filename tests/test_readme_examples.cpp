// The README's code examples, kept compiling and running.
#include <gtest/gtest.h>

#include "cpu/edge_kernels.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "test_meshes.hpp"

TEST(Readme, KernelExample) {
    using namespace edgefem;
    Mesh mesh = read_mesh(test::test_data_dir() + "/small0.node");
    validate_mesh(mesh);
    Topology topo = build_topology(mesh);
    Coefficients coef = compute_coefficients(mesh, topo, Material{1e5, 0.3, 1000});
    EdgeModel<double> model = make_edge_model<double>(topo, coef);

    std::vector<double> u(mesh.X.size(), 0.0), f(u.size());
    EdgeState<double> state;
    double W = edge_forces<ModelKind::FE, true>(model, u.data(), f.data(), state);
    EdgeStiffness<double> K;
    edge_stiffness_all<ModelKind::FE>(model, state, K);
    EXPECT_EQ(W, 0.0);
}

TEST(Readme, SimulationExample) {
    edgefem::SceneFile file = edgefem::load_scene(edgefem::test::test_data_dir() + "/../../examples/scenes/cantilever.json");
    edgefem::Simulator<double> sim(file.scene);
    for (int k = 0; k < 100; ++k) {
        sim.external_forces()[3 * 42 + 2] = -0.01;
        const edgefem::StepStats& st = sim.step();
        (void)st;
    }
    std::span<double> u = sim.displacement();
    // The push moved vertex 42 further down than gravity alone does.
    edgefem::Simulator<double> free_fall(file.scene);
    for (int k = 0; k < 100; ++k) free_fall.step();
    EXPECT_LT(u[3 * 42 + 2], free_fall.displacement()[3 * 42 + 2] - 1e-5);
}
