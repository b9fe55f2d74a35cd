// The core's ElasticOperator contract (elastic_operator.hpp): build_stiffness
// builds K at the last forces() call's u, whatever came between (energy(),
// or a force call that kept no state: keep_state(false) runs the force on a
// ring, FormRing), and the forces do not depend on keep_state; an explicit
// Simulator runs its forces on the ring and steps bitwise as with the state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "edgefem/parallel/cpu_backend.hpp"
#include "lab/deformations.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"
#include "cantilever.hpp"
#include "forwarding_operator.hpp"

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
    auto op = make_cpu_operator<double>(mesh, mat, ModelKind::FE, Method::Edge);
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

namespace {

// Forwards everything; keep_state only when `forward`.
class KeepStateSpy final : public test::ForwardingOperator {
public:
    KeepStateSpy(std::unique_ptr<ElasticOperator<double>> op, bool forward)
        : ForwardingOperator(std::move(op)), forward_(forward) {}
    void keep_state(bool keep) override {
        if (forward_) op_->keep_state(keep);
    }
    bool forces_stored_state() const override { return op_->forces_stored_state(); }

private:
    bool forward_;
};

}  // namespace

TEST(ElasticOperator, ExplicitStepsOnTheRingMatchStepsWithTheState) {
    Scene scene = test::clamped_box_scene(30, 12, 12, 1e5);
    scene.mesh = tiled_box();
    scene.fixed.clear();  // clamped at x = min again, in the RCM numbering
    double xmin = std::numeric_limits<double>::infinity();
    for (index_t v = 0; v < scene.mesh.num_vertices(); ++v) xmin = std::min(xmin, scene.mesh.X[3 * v]);
    for (index_t v = 0; v < scene.mesh.num_vertices(); ++v)
        if (scene.mesh.X[3 * v] < xmin + 1e-9) scene.fixed.push_back(v);
    ASSERT_FALSE(scene.fixed.empty());
    scene.integrator = Integrator::Explicit;
    scene.dt = 2e-6;
    const KeepStateSpy* spy[2] = {nullptr, nullptr};
    auto factory = [&spy](int i) -> OperatorFactory<double> {
        return [&spy, i](const Mesh& m, const Materials& mat, ModelKind k, Method me) {
            auto op = std::make_unique<KeepStateSpy>(make_cpu_operator<double>(m, mat, k, me), i == 0);
            spy[i] = op.get();
            return std::unique_ptr<ElasticOperator<double>>(std::move(op));
        };
    };
    Simulator<double> ring(scene, nullptr, factory(0)), kept(scene, nullptr, factory(1));
    for (int k = 0; k < 5; ++k) {
        ring.step();
        kept.step();
    }
    ASSERT_TRUE(spy[0] && spy[1]);
    EXPECT_FALSE(spy[0]->forces_stored_state());  // the explicit scene said keep_state(false)
    EXPECT_TRUE(spy[1]->forces_stored_state());
    const auto a = ring.displacement(), b = kept.displacement();
    EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin()));
    double moved = 0;
    for (double x : a) moved = std::max(moved, std::abs(x));
    EXPECT_GT(moved, 0.0);
}
