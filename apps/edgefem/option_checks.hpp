// Checks of command-line values shared by the edgefem subcommands.
#pragma once

#include <limits>
#include <string>

#include <CLI/CLI.hpp>

namespace edgefem::cli {

// CLI11's Range/PositiveNumber/NonNegativeNumber print DBL_MAX in full and
// even reject values inside the range they print; these name the bound.
// CLI11 prefixes the option's name: "--cg-iters: expected an integer >= 1, got '0'".
CLI::Validator int_in_range(long long min, long long max = std::numeric_limits<long long>::max());
// A finite number of seconds in (0, max]: inf or 1e300 would never end or
// overflow a step count.
CLI::Validator seconds_at_most(double max);
// A path that is not the empty string ("" would silently mean a default or a
// hidden file).
CLI::Validator non_empty_path();
// Adds to every numeric option of `app` and its subcommands, ahead of its
// other checks, a check that rejects an empty value ("--poisson: empty
// value"): CLI11 would convert "" to 0. Call after adding the subcommands.
void reject_empty_numbers(CLI::App& app);

// Throws Error naming `option` when `path` cannot be created or written (its
// folder is missing or not writable, or it is a folder): checked before a long
// run, so that the run is not lost to a typo. Creates nothing.
void check_writable(const std::string& option, const std::string& path);

}  // namespace edgefem::cli
