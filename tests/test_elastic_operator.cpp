// The core's ElasticOperator contract (elastic_operator.hpp): build_stiffness
// builds K at the last forces() call's u, whatever came between (energy(),
// or a force call that kept no state: keep_state(false) runs the force on a
// ring, FormRing), and the forces do not depend on keep_state.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "edgefem/core/deformations.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

// K x for a fixed x at the operator's last build.
std::vector<double> k_times(ElasticOperator<double>& op, const std::vector<double>& x) {
    std::vector<double> y(x.size());
    op.multiply(x.data(), y.data());
    return y;
}

// Large enough for the tet-local form to run in tiles (more than 2 x 1024
// batches) with a ring shorter than the edge list; RCM-numbered, as the
// simulator runs it.
Mesh tiled_box() {
    const Mesh box = make_box(30, 12, 12);
    return permute_mesh(box, vertex_ordering(box, Ordering::RCM));
}

void check_contract(const Mesh& mesh, bool expect_ring) {
    const Materials mat(Material{1e5, 0.3, 1000});
    auto op = make_elastic_operator<double>(mesh, mat, ModelKind::FE, Method::Edge);
    const std::vector<double> u = deformation_displacement(mesh, Deformation::Twist);
    const std::vector<double> w = deformation_displacement(mesh, Deformation::Random);
    std::vector<double> x(u.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.37 * double(i));

    // Reference: forces keeping the state, then K.
    std::vector<double> f0(u.size()), f1(u.size(), 7.0);
    const double W0 = op->forces(u.data(), f0.data(), true);
    EXPECT_TRUE(op->forces_stored_state());
    op->build_stiffness(false);
    const std::vector<double> Kx0 = k_times(*op, x);

    // Without keeping the state: the same forces and energy, bitwise; K
    // rebuilt at the same u (the stored state is at w by then).
    op->forces(w.data(), f1.data(), false);
    op->keep_state(false);
    const double W1 = op->forces(u.data(), f1.data(), true);
    EXPECT_EQ(op->forces_stored_state(), !expect_ring);
    EXPECT_TRUE(f1 == f0);
    EXPECT_EQ(W1, W0);
    op->build_stiffness(false);
    EXPECT_TRUE(k_times(*op, x) == Kx0);

    // energy() at another u between forces() and build_stiffness() leaves K
    // at the forces' u, with and without the state kept.
    for (bool keep : {true, false}) {
        SCOPED_TRACE(keep ? "state kept" : "no state");
        op->keep_state(keep);
        op->forces(u.data(), f1.data(), false);
        const double Ww = op->energy(w.data());
        EXPECT_TRUE(std::isfinite(Ww));
        EXPECT_NE(Ww, W0);
        op->build_stiffness(false);
        EXPECT_TRUE(k_times(*op, x) == Kx0);
    }
}

}  // namespace

TEST(ElasticOperator, StiffnessFollowsTheLastForcesOnTiles) {
    check_contract(tiled_box(), /*expect_ring=*/true);
}

TEST(ElasticOperator, StiffnessFollowsTheLastForcesInOneTile) {
    check_contract(make_box(5, 4, 3), /*expect_ring=*/false);
}
