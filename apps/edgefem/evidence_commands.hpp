// The evidence subcommands (docs/benchmarks.md): `edgefem stress`, the
// numerical stability stress suite, `edgefem accuracy`, run time against
// error on standard scenes, and `edgefem bench-layouts`, the memory-layout
// comparison (docs/layouts.md). Wiring only: the stress suite lives in core
// (edgefem/core/stress_suite.hpp).
#pragma once

#include <CLI/CLI.hpp>

namespace edgefem::cli {

void add_stress_command(CLI::App& app);
void add_accuracy_command(CLI::App& app);
void add_bench_layouts_command(CLI::App& app);

}  // namespace edgefem::cli
