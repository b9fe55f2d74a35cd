// The numerical stability stress suite (`edgefem stress`, tests/test_stress_suite.cpp):
// hard cases x integrators, each simulated for a fixed time, with a verdict
// and its reason.
//
// Every case runs on a small generated mesh (double precision, serial) with
// mass-proportional damping alpha = 10 /s (the full suite's
// compress-20%-beta adds stiffness damping beta = 1e-3 s, without verlet,
// which takes no beta), no gravity, the library's default
// solver settings except solver.max_step_halvings = 3 and the simulator's
// energy guard set to the suite's own bound (solver.max_energy_growth =
// kEnergyGrowthFactor), so the rest shape is the only equilibrium it should
// return to. A step that makes the energy grow without a source fails and is
// retried as halves, so an energy-injecting step (semi-implicit on
// 0.1-degree slivers, or at Y = 1e9) is caught where it happens instead of
// running on as silent garbage; where halving does not help, the run fails
// cleanly. (With the default guard of 10, halved explicit steps held runs at
// ~9x their release energy without an error.) The verdict rules and
// expectations below do not depend on it. A case is a sequence of
// phases: an optional driven phase (prescribed vertices moved: compression,
// twist), then a free phase ("release") until the case's simulated time.
//
// Verdicts:
//  * pass: every state finite, the total energy (kinetic + elastic) of the
//    free phase never above kEnergyGrowthFactor x its value at release, and,
//    where the case requires it, the final displacement within
//    kRecoveryTolerance x the body's size of the rest shape;
//  * failed cleanly: the Simulator threw SimulationError (the message is
//    kept), which is acceptable; flagged expected or unexpected against
//    the case's a-priori expectation (explicit steps above the CFL estimate
//    are expected to fail);
//  * FAIL: silent garbage (non-finite energy without an error, energy growth
//    beyond the bound without an error, any other exception), or no
//    recovery where the case requires it: a bug.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "edgefem/core/scene.hpp"

namespace edgefem {

inline constexpr double kEnergyGrowthFactor = 2.0;  // free phase: E(t) <= 2 E(release)
inline constexpr double kRecoveryTolerance = 1e-3;  // max |u| / body size at the end

// Reported: recovery was required and not reached, but the run ended with
// tets inverted, which every step's StepStats::inverted_tets tells the
// caller (StVK has inverted equilibria: a sliver flipped through its own
// plane stores almost no energy): a failure, not a silent one.
enum class StressVerdict { Pass, CleanFailure, Reported, Fail };
enum class StressExpectation { Pass, Fail, Either };

const char* to_string(StressVerdict v);     // "pass", "failed cleanly", "reported", "FAIL"
const char* to_string(StressExpectation e); // "pass", "fail", "either"

struct StressResult {
    std::string group;        // dt, young, poisson, compress, damping, invert, noise, sliver, twist
    std::string name;         // e.g. "dt=1/30", "young=1e9"
    std::string integrator;   // to_string(Integrator): explicit, semi-implicit, implicit, newmark, ...
    double dt = 0;
    double seconds = 0;       // simulated time asked for
    double simulated = 0;     // simulated time reached
    long steps = 0;
    StressExpectation expected = StressExpectation::Pass;
    StressVerdict verdict = StressVerdict::Pass;
    bool unexpected = false;  // a verdict against the expectation (pass or clean failure)
    std::string reason;       // the verdict's reason, or the SimulationError message
    bool recovery_required = false;
    double recovery = 0;      // max |u| / body size at the end (NaN when not reached)
    double energy_growth = 0; // max E(t) / E(release) over the free phase
    index_t max_inverted = 0; // most inverted tets in any step
    index_t final_inverted = 0; // inverted tets after the last step
    double dt_cfl = 0;        // the explicit stability estimate for this case (s)
    long unconverged_solves = 0;  // semi-implicit steps whose CG stopped above its tolerance
    long halvings = 0;        // step halvings used (solver.max_step_halvings = 3)
    double wall_s = 0;
};

struct StressOptions {
    bool quick = false;       // a subset of cases, `quick_seconds` each
    double seconds = 10;      // simulated time of each run (full suite)
    double quick_seconds = 2;
    std::string filter;       // run only cases whose "group name integrator" contains it
    std::function<void(const StressResult&)> on_result;  // progress (after each run)
};

std::vector<StressResult> run_stress_suite(const StressOptions& opts);

// One line per result, fixed-width columns, and a summary line.
std::string format_stress_table(const std::vector<StressResult>& results);
// The results as a JSON array (for bench/report).
std::string stress_results_json(const std::vector<StressResult>& results);

}  // namespace edgefem
