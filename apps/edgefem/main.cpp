// edgefem: command-line front end of the edgefem library. Every error is one
// line "edgefem: error: <message>" on stderr and exit code 2, 3 when a
// simulation fails (a SimulationError: unstable step, failed solve), or 4
// when a file cannot be written (an IoError or a filesystem error: disk
// full, no permission, a file where a folder should be).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "common.hpp"
#include "evidence_commands.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/retain_freed_memory.hpp"
#include "edgefem/core/simulator.hpp"
#include "sim_common.hpp"

namespace {

constexpr int kErrorExit = 2;
constexpr int kSimulationFailedExit = 3;
constexpr int kIoErrorExit = 4;

int fail(const std::string& text, int code = kErrorExit) {
    // One line of printable text (no terminal escape codes, no 100 MB path),
    // whatever the message holds.
    std::string message = edgefem::printable(text);
    for (char& c : message)
        if (c == '\n') c = ' ';
    constexpr std::size_t kMaxMessage = 4000;
    if (message.size() > kMaxMessage) message = message.substr(0, kMaxMessage) + "...";
    std::fprintf(stderr, "edgefem: error: %s\n", message.c_str());
    return code;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"edgefem " EDGEFEM_VERSION
                 ": edge-based StVK tetrahedral FEM (Kikuuwe et al. 2009) and the per-tet baseline",
                 "edgefem"};
    app.set_version_flag("--version", EDGEFEM_VERSION);
    // A write past the file size limit (ulimit -f) is an error to report
    // (EFBIG), not a signal that kills the program mid-frame.
    std::signal(SIGXFSZ, SIG_IGN);
    // The AMG's refreshes free and allocate megabytes each time: kept for
    // reuse, not faulted in again (docs/parallel.md, "Set-up on a VM").
    edgefem::retain_freed_memory();
    bool no_memory_check = false;
    app.add_flag("--no-memory-check", no_memory_check,
                 "Build models even when their estimated memory (1000 bytes per tet) exceeds what is available "
                 "(same as EDGEFEM_NO_MEMORY_CHECK=1)");
    // Set before anything runs: the subcommands' callbacks run inside parse().
    for (int i = 1; i < argc && argv[i][0] == '-'; ++i)
        if (std::string(argv[i]) == "--no-memory-check") ::setenv("EDGEFEM_NO_MEMORY_CHECK", "1", 1);
    app.require_subcommand(1);
    // Subcommands inherit this footer when they are added: those without a
    // MESH (simulate, static, stress, accuracy) set their own.
    app.footer(
        "MESH is a TetGen .node/.ele file or their common prefix, a Gmsh .msh, MEDIT .mesh or Vega .veg\n"
        "file, or box:NXxNYxNZ, a generated box of NX x NY x NZ cubes of 0.01 m split into 6 tets each\n"
        "(box:10x5x4 is the paper's 1,200-tet box), so no files are needed:\n"
        "  edgefem info box:10x5x4\n"
        "  edgefem forces box:10x5x4 --young 1e5 --poisson 0.3 --deform twist --out twist\n"
        "  edgefem bench box:10x5x4 --kernel force --method tet\n"
        "  edgefem simulate examples/scenes/cantilever.json --out cantilever-out\n"
        "Errors print one line 'edgefem: error: ...' to stderr. Exit codes: 0 ok, 2 bad input,\n"
        "3 simulation failed (unstable step or failed solve; the message names the step and vertex),\n"
        "4 a file could not be written (the message names it).");
    edgefem::cli::add_info_command(app);
    edgefem::cli::add_forces_command(app);
    edgefem::cli::add_bench_command(app);
    edgefem::cli::add_simulate_command(app);
    edgefem::cli::add_static_command(app);
    edgefem::cli::add_stress_command(app);
    edgefem::cli::add_accuracy_command(app);
    edgefem::cli::add_bench_layouts_command(app);
    edgefem::cli::reject_empty_numbers(app);
    // CLI11 would report a mistyped subcommand as "A subcommand is required".
    if (argc > 1 && argv[1][0] != '-') {
        bool known = false;
        for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
            known = known || sub->get_name() == argv[1];
        if (!known) return fail(std::string("unknown subcommand '") + argv[1] + "' (expected info, forces, bench, bench-layouts, simulate, static, stress or accuracy)");
    }
    try {
        app.parse(argc, argv);  // runs the selected subcommand's callback
    } catch (const CLI::Success& e) {
        return app.exit(e);  // --help, --version
    } catch (const CLI::ParseError& e) {
        return fail(e.what());
    } catch (const edgefem::SimulationError& e) {
        return fail(std::string("simulation failed: ") + e.what(), kSimulationFailedExit);
    } catch (const edgefem::IoError& e) {
        return fail(e.what(), kIoErrorExit);
    } catch (const std::filesystem::filesystem_error& e) {
        // e.what() is "filesystem error: <op>: <reason> [<path>]".
        return fail(std::string(e.what()), kIoErrorExit);
    } catch (const std::bad_alloc&) {
        // A bare "std::bad_alloc" names nothing.
        return fail("out of memory (the input needs more memory than is available: try a smaller mesh)");
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    return 0;
}
