// A short subset of the numerical stability stress suite (`edgefem stress`,
// edgefem/core/stress_suite.hpp), correctness only (no timing): released
// cases that must pass with the unconditionally stable integrators, an
// explicit step far above the stability limit that must fail cleanly (a
// SimulationError naming the step, never a silent NaN), and the table/JSON.
#include <gtest/gtest.h>

#include <cmath>

#include "edgefem/core/stress_suite.hpp"

using namespace edgefem;

namespace {

std::vector<StressResult> run(const std::string& filter, double seconds = 1.0) {
    StressOptions o;
    o.quick = true;
    o.quick_seconds = seconds;
    o.filter = filter;
    return run_stress_suite(o);
}

}  // namespace

TEST(StressSuite, RandomInitialStateRecoversWithEveryIntegrator) {
    const auto rs = run("random-state");
    ASSERT_EQ(rs.size(), 3u);
    for (const auto& r : rs) {
        SCOPED_TRACE(r.integrator + ": " + r.reason);
        EXPECT_EQ(r.verdict, StressVerdict::Pass);
        EXPECT_TRUE(std::isfinite(r.recovery));
        EXPECT_LE(r.recovery, kRecoveryTolerance);
        EXPECT_LE(r.energy_growth, kEnergyGrowthFactor);
        EXPECT_NEAR(r.simulated, 1.0, 1e-9);
    }
}

TEST(StressSuite, ExplicitFarAboveTheStabilityLimitFailsCleanly) {
    const auto rs = run("dt=1/30 explicit");
    ASSERT_EQ(rs.size(), 1u);
    const StressResult& r = rs[0];
    EXPECT_EQ(r.expected, StressExpectation::Fail);
    EXPECT_EQ(r.verdict, StressVerdict::CleanFailure) << r.reason;
    EXPECT_NE(r.reason.find("failed cleanly with error: step "), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find("non-finite"), std::string::npos) << r.reason;
    EXPECT_FALSE(r.unexpected);
}

TEST(StressSuite, ImplicitIntegratorsPassTheLargeStepAndTheInvertedTet) {
    for (const std::string filter : {"dt=1/30 semi-implicit", "dt=1/30 implicit", "vertex-through-face semi-implicit",
                                     "vertex-through-face implicit"}) {
        const auto rs = run(filter);
        ASSERT_EQ(rs.size(), 1u) << filter;
        EXPECT_EQ(rs[0].verdict, StressVerdict::Pass) << filter << ": " << rs[0].reason;
    }
}

TEST(StressSuite, TwistedBarIsReleasedAndRecoversImplicitly) {
    const auto rs = run("twist-180 semi-implicit", 2.0);
    ASSERT_EQ(rs.size(), 1u);
    EXPECT_EQ(rs[0].verdict, StressVerdict::Pass) << rs[0].reason;
    EXPECT_LE(rs[0].recovery, kRecoveryTolerance);
}

TEST(StressSuite, NoRunOfTheQuickSuiteIsSilentNaN) {
    // Whatever the verdict, a non-finite state must surface as a
    // SimulationError: a FAIL may be energy growth or no recovery, never a
    // NaN the simulator did not report.
    for (const auto& r : run("", 0.5)) {
        SCOPED_TRACE(r.name + " " + r.integrator + ": " + r.reason);
        EXPECT_EQ(r.reason.find("and no error by the end"), std::string::npos);
        EXPECT_EQ(r.reason.find("unexpected exception"), std::string::npos);
    }
}

TEST(StressSuite, TableAndJsonListEveryRun) {
    const auto rs = run("random-state explicit", 1.0);
    ASSERT_EQ(rs.size(), 1u);
    const std::string table = format_stress_table(rs);
    EXPECT_NE(table.find("random-state"), std::string::npos);
    EXPECT_NE(table.find("summary: 1 runs: 1 pass"), std::string::npos) << table;
    const std::string json = stress_results_json(rs);
    EXPECT_NE(json.find("\"verdict\": \"pass\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"integrator\": \"explicit\""), std::string::npos) << json;
}
