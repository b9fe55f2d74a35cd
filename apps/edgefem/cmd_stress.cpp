// `edgefem stress [--quick]`: the numerical stability stress suite
// (core/include/edgefem/core/stress_suite.hpp): hard cases x integrators, a
// pass / failed-cleanly / reported / FAIL table with the reason. Exit code 3
// when any run is a FAIL (silent garbage, or no recovery where required and
// nothing reported); clean failures (a SimulationError) and reported ones
// (tets inverted at the end, in StepStats) exit 0.
#include <cstdio>
#include <fstream>

#include "edgefem/core/error.hpp"
#include "edgefem/core/simulator.hpp"
#include "lab/stress_suite.hpp"
#include "option_checks.hpp"
#include "evidence_commands.hpp"

namespace edgefem::cli {

void add_stress_command(CLI::App& app) {
    struct Options {
        bool quick = false;
        double seconds = 10;
        std::string filter, json;
    };
    auto opts = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("stress", "Numerical stability stress suite: hard cases x integrators, pass/fail table");
    cmd->add_flag("--quick", opts->quick, "A subset of the cases, 2 simulated seconds each (well under a minute)");
    // Bounded: a huge value overflows the step count (lround(seconds / dt))
    // and would report a solver FAIL for what is a bad option.
    cmd->add_option("--seconds", opts->seconds, "Simulated seconds per run of the full suite, at most 3600")
        ->check(seconds_at_most(3600))
        ->capture_default_str();
    cmd->add_option("--filter", opts->filter, "Run only cases whose 'group name integrator' contains this text");
    cmd->add_option("--json", opts->json, "Also write the results as JSON to this file")->check(non_empty_path());
    cmd->footer(
        "Verdicts: pass (finite, energy of the free phase <= 2x its value at release, recovered to within\n"
        "1e-3 of the body size where required); failed cleanly (a SimulationError: acceptable; '(!)' marks\n"
        "one against the a-priori expectation); reported (no recovery where required, but the run ends\n"
        "with tets inverted, which every step's stats report: StVK's inverted equilibria); FAIL (silent\n"
        "garbage, or no recovery with nothing reported: a bug).\n"
        "Exit codes: 0 no FAIL, 2 bad input, 3 at least one FAIL.");
    cmd->callback([opts] {
        // Before the suite, not after it: a typo in the path would lose the run.
        if (!opts->json.empty()) check_writable("--json", opts->json);
        StressOptions so;
        so.quick = opts->quick;
        so.seconds = opts->seconds;
        so.filter = opts->filter;
        so.on_result = [](const StressResult& r) {
            std::fprintf(stderr, "stress: %s / %s: %s (%.2f s)\n", r.name.c_str(), r.integrator.c_str(),
                         to_string(r.verdict), r.wall_s);
        };
        const auto results = run_stress_suite(so);
        if (results.empty()) throw InvalidArgument("--filter '" + opts->filter + "' selects no stress case");
        std::fputs(format_stress_table(results).c_str(), stdout);
        std::fflush(stdout);
        if (!opts->json.empty()) {
            std::ofstream out(opts->json);
            out << stress_results_json(results);
            if (!out) throw Error("cannot write " + opts->json);
        }
        int fails = 0;
        for (const auto& r : results) fails += r.verdict == StressVerdict::Fail;
        if (fails) throw SimulationError("stress suite: " + std::to_string(fails) + " run(s) FAIL (see the table)", 0);
    });
}

}  // namespace edgefem::cli
