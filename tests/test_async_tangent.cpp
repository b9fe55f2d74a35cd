// The asynchronous tangent (parallel/async_tangent.hpp): its first step is
// the synchronous step bitwise (the first K is built in the foreground),
// later steps use a K that lags by a build, so a damped swing stays finite,
// settles where the synchronous run settles, and the operator shuts its
// worker down cleanly even with a build in flight.
#include <gtest/gtest.h>

#include <cmath>

#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/async_tangent.hpp"
#include "cantilever.hpp"

using namespace edgefem;

namespace {

// The tests' cantilever (test_support/cantilever.hpp), lightly damped.
Scene cantilever() {
    Scene s = test::cantilever_scene();
    s.rayleigh_alpha = 20;
    return s;
}

double max_abs_diff(std::span<const double> a, std::span<const double> b) {
    double d = 0;
    for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
    return d;
}

double max_abs(std::span<const double> a) {
    double d = 0;
    for (double x : a) d = std::max(d, std::abs(x));
    return d;
}

}  // namespace

TEST(AsyncTangent, FirstStepIsTheSynchronousStep) {
    // The same operators as async_tangent_factory's default inner ones.
    Simulator<double> sync(cantilever(), nullptr, cpu_operator_factory<double>());
    Simulator<double> async(cantilever(), nullptr, async_tangent_factory<double>());
    sync.step();
    async.step();
    const auto a = async.displacement(), s = sync.displacement();
    EXPECT_EQ(max_abs_diff(a, s), 0.0);
}

TEST(AsyncTangent, SettlesWhereTheSynchronousRunSettles) {
    Simulator<double> sync(cantilever());
    Simulator<double> async(cantilever(), nullptr, async_tangent_factory<double>());
    for (int k = 0; k < 600; ++k) {
        sync.step();
        async.step();
        for (double x : async.displacement()) ASSERT_TRUE(std::isfinite(x)) << "step " << k;
    }
    const auto a = async.displacement(), s = sync.displacement();
    // The tip sags by centimetres; after 0.6 s of damped swing both runs sit
    // near the same static deflection (a lagged K changes the path, not the
    // equilibrium: the forces are always current).
    EXPECT_GT(max_abs(s), 1e-3);
    EXPECT_LT(max_abs_diff(a, s), 0.02 * max_abs(s));
}

TEST(AsyncTangent, ShutsDownWithABuildInFlight) {
    for (int k = 0; k < 20; ++k) {
        Simulator<double> sim(cantilever(), nullptr, async_tangent_factory<double>());
        sim.step();
        sim.step();  // starts a background build; the destructor must join it
    }
    SUCCEED();
}
