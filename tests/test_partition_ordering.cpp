// Orderings: each is a permutation, each leaves the physics unchanged up to
// summation order, and the locality orderings actually improve locality.
#include <gtest/gtest.h>

#include "lab/deformations.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/partition/ordered_simulator.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"
#include "cantilever.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {
std::vector<double> forces(const Mesh& mesh, const std::vector<double>& u) {
    const auto m = test::make_models<double>(mesh);
    std::vector<double> f(u.size());
    EdgeState<double> st;
    edge_forces<ModelKind::FE, false>(m.edge, u.data(), f.data(), st);
    return f;
}
}  // namespace

TEST(Ordering, EveryOrderingIsAPermutationAndKeepsTheForces) {
    for (const auto& [name, mesh] : test::test_meshes(10000)) {
        const auto u = deformation_displacement(mesh, Deformation::Twist);
        const auto f_ref = forces(mesh, u);
        const Topology topo_ref = build_topology(mesh);
        for (Ordering o : all_orderings()) {
            SCOPED_TRACE(name + " " + to_string(o));
            const auto p = vertex_ordering(mesh, o);
            ASSERT_EQ(p.size(), std::size_t(mesh.num_vertices()));
            EXPECT_NO_THROW(invert_permutation(p));
            const Mesh pm = permute_mesh(mesh, p);
            const Topology topo = build_topology(pm);
            EXPECT_EQ(topo.num_edges(), topo_ref.num_edges());
            EXPECT_EQ(topo.num_tseps(), topo_ref.num_tseps());
            // Same deformation, carried into the new numbering and back.
            std::vector<double> u_int(u.size()), f_user(u.size());
            to_internal<double>(u, u_int, p);
            const auto f_int = forces(pm, u_int);
            to_user<double>(f_int, f_user, p);
            EXPECT_LE(test::rel_diff(f_user, f_ref), 1e-13);
            // Orientation kept: every tet still positive.
            for (index_t t = 0; t < pm.num_tets(); ++t) {
                const index_t* v = &pm.tets[4 * t];
                ASSERT_GT(signed_volume(&pm.X[3 * v[0]], &pm.X[3 * v[1]], &pm.X[3 * v[2]], &pm.X[3 * v[3]]), 0);
            }
        }
    }
}

TEST(Ordering, LocalityOrderingsBeatTheShuffle) {
    const Mesh mesh = make_box(12, 10, 8);
    const double random = ordering_bandwidth(mesh, vertex_ordering(mesh, Ordering::Random)).near;
    for (Ordering o : {Ordering::RCM, Ordering::Morton, Ordering::NestedDissection, Ordering::MetisKway}) {
        SCOPED_TRACE(to_string(o));
        // Share of neighbours within 64 positions: ~0.1 shuffled, 0.58-0.84 here.
        EXPECT_GT(ordering_bandwidth(mesh, vertex_ordering(mesh, o)).near, 4 * random);
    }
    // RCM is a bandwidth minimiser: no worse than the input's lexicographic grid order.
    EXPECT_LE(ordering_bandwidth(mesh, vertex_ordering(mesh, Ordering::RCM)).max,
              ordering_bandwidth(mesh, vertex_ordering(mesh, Ordering::Input)).max);
}

TEST(Ordering, MetisPartsAreContiguousAndBadNamesRejected) {
    const Mesh mesh = make_box(20, 10, 10);
    OrderingOptions opt;
    opt.part_bytes = 64 * 1024;  // many small parts
    const auto p = vertex_ordering(mesh, Ordering::MetisKway, opt);
    EXPECT_NO_THROW(invert_permutation(p));
    EXPECT_THROW(parse_ordering("hilbert"), InvalidArgument);
    for (Ordering o : all_orderings()) EXPECT_EQ(parse_ordering(to_string(o)), o);
    EXPECT_THROW(invert_permutation({0, 0, 1}), InvalidArgument);
}

// The simulator on a renumbered scene, seen through the user's numbering,
// follows the same trajectory as the simulator on the scene as given.
TEST(Ordering, OrderedSimulatorIsInvisibleToTheUser) {
    Scene s = edgefem::test::clamped_box_scene(6, 3, 3, 5e4);
    s.prescribed.push_back({s.mesh.num_vertices() - 1, {0.035, 0.02, 0.02}});
    s.solver.linear_solver = LinearSolver::Direct;
    Simulator<double> plain(s);
    std::vector<double> push(s.mesh.X.size(), 0.0);
    push[3 * 40 + 1] = 0.02;
    for (Ordering o : all_orderings()) {
        SCOPED_TRACE(to_string(o));
        OrderedSimulator<double> ordered(s, o);
        ordered.set_external_forces(push);
        if (o == Ordering::Input) std::copy(push.begin(), push.end(), plain.external_forces().begin());
        for (int k = 0; k < 10; ++k) {
            ordered.step();
            if (o == Ordering::Input) plain.step();
        }
        std::vector<double> u(push.size());
        ordered.get_displacement(u);
        const std::vector<double> ref(plain.displacement().begin(), plain.displacement().end());
        EXPECT_LE(test::rel_diff(u, ref), 1e-10);
        const auto x = ordered.positions();
        EXPECT_NEAR(x[3 * (s.mesh.num_vertices() - 1)], s.mesh.X[3 * (s.mesh.num_vertices() - 1)] + ref[3 * (s.mesh.num_vertices() - 1)], 1e-12);
    }
}

// Arrays of the wrong length are errors, not reads or writes past their end.
TEST(Ordering, OrderedSimulatorChecksArrayLengths) {
    const Scene s = edgefem::test::clamped_box_scene(6, 2, 2);
    OrderedSimulator<double> sim(s, Ordering::RCM);
    const std::size_t n = 3 * std::size_t(s.mesh.num_vertices());
    for (const std::size_t len : {std::size_t(0), std::size_t(6), n - 1, n + 3}) {
        std::vector<double> a(len, 0.0);
        EXPECT_THROW(sim.set_displacement(a), InvalidArgument) << len;
        EXPECT_THROW(sim.set_velocity(a), InvalidArgument) << len;
        EXPECT_THROW(sim.set_external_forces(a), InvalidArgument) << len;
        EXPECT_THROW(sim.get_displacement(a), InvalidArgument) << len;
        EXPECT_THROW(sim.get_velocity(a), InvalidArgument) << len;
        EXPECT_THROW(sim.get_forces(a), InvalidArgument) << len;
    }
    std::vector<double> a(n, 0.0);
    EXPECT_NO_THROW(sim.set_displacement(a));
    EXPECT_NO_THROW(sim.get_forces(a));
}

// An explicit step far past the stability limit: the error an
// OrderedSimulator throws names the vertex in the user's numbering (vertex()
// and the message), the one the simulator on the renumbered scene names.
TEST(Ordering, OrderedSimulatorErrorsNameUserVertices) {
    Scene s = edgefem::test::clamped_box_scene(6, 3, 3, 1e9);
    s.integrator = Integrator::Explicit;
    s.dt = 0.01;
    for (Ordering o : {Ordering::Input, Ordering::Random, Ordering::RCM}) {
        SCOPED_TRACE(to_string(o));
        const std::vector<index_t> new_of_old = vertex_ordering(s.mesh, o);
        Simulator<double> internal(permute_scene(s, new_of_old));
        index_t internal_vertex = -1;
        try {
            for (int k = 0; k < 200; ++k) internal.step();
        } catch (const SimulationError& e) {
            internal_vertex = e.vertex();
        }
        ASSERT_GE(internal_vertex, 0) << "the scene should blow up and name a vertex";
        OrderedSimulator<double> ordered(s, o);
        bool thrown = false;
        try {
            for (int k = 0; k < 200; ++k) ordered.step();
        } catch (const SimulationError& e) {
            thrown = true;
            ASSERT_GE(e.vertex(), 0);
            EXPECT_EQ(new_of_old[e.vertex()], internal_vertex);
            const std::string msg = e.what(), name = "vertex " + std::to_string(e.vertex());
            const std::size_t at = msg.find(name);
            ASSERT_NE(at, std::string::npos) << msg;
            EXPECT_FALSE(at + name.size() < msg.size() && std::isdigit(static_cast<unsigned char>(msg[at + name.size()])))
                << msg;
        }
        EXPECT_TRUE(thrown);
    }
}
