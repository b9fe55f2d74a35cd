// How and where a simulation runs: one set of options for the edgefem
// program, the Python module, the C API and C++ applications, with the same
// defaults everywhere: every core of the machine through the adaptive
// executor (which runs the loops serially where that measured faster, with
// the same results), the default scatter variant, and the vertices renumbered
// by RCM for memory locality (inputs and outputs stay in the mesh's
// numbering).
//
//   RunOptions run;                                   // the defaults
//   run.threads = 4;
//   auto sim = make_simulator<double>(scene, run);    // an OrderedSimulator
//   sim->step();
#pragma once

#include <memory>
#include <string>

#include "edgefem/core/executor.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/partition/ordered_simulator.hpp"

namespace edgefem {

struct RunOptions {
    // auto: the CPU back-end on the pool executor with `threads` threads
    //   (its serial loops when that is one thread);
    // reference: the reference back-end (plain serial loops, the oracle; slow);
    // serial: the CPU back-end's serial loops (one thread);
    // omp, tbb, pool: the CPU back-end's threaded kernels on OpenMP, oneTBB or
    //   the spinning thread pool;
    // cuda: the GPU back-end (cuda_backend.hpp; an error naming the reason
    //   where it cannot run: a build without CUDA, no device).
    std::string backend = "auto";
    // Threads of auto/omp/tbb/pool; 0: every hardware thread.
    int threads = 0;
    // How the threaded kernels resolve concurrent writes: auto (owner when
    // the numbering has locality, else gather), colour, gather, atomic,
    // private or owner. With serial: that variant on one thread.
    std::string variant = "auto";
    // static | dynamic: how chunks go to threads (never changes a result).
    std::string schedule = "dynamic";
    // Time the first calls of every loop on the threads and on one thread,
    // and run them all where that was faster in sum (same results).
    bool adaptive = true;
    // Vertex renumbering for locality: input (none), random, rcm, morton,
    // nd, metis.
    std::string ordering = "rcm";
    // Where the edge FE stiffness takes its pair terms from: tet-local or
    // tsep-list (the CPU back-end; the reference always uses the TSEP list).
    std::string layout = "tet-local";
};

// Throws InvalidArgument naming the option, its value and what it accepts
// (and for a variant with the reference back-end).
void validate(const RunOptions& run);

// The executor the solvers' vector work and the threaded kernels run on:
// null for reference, cuda and serial (without a variant), else the chosen one,
// wrapped in an AdaptiveExecutor when run.adaptive.
std::shared_ptr<const Executor> make_run_executor(const RunOptions& run);

// The elastic operators the options describe, on `executor` (the result of
// make_run_executor).
template <class S>
OperatorFactory<S> make_run_factory(const RunOptions& run, std::shared_ptr<const Executor> executor);

// The back-end the options describe: the CUDA back-end for cuda, else the
// CPU back-end (reference: the reference operator) on `executor`.
template <class S>
std::shared_ptr<const Backend<S>> make_run_backend(const RunOptions& run, std::shared_ptr<const Executor> executor);

// The simulator the options describe (validated first): renumbered by
// run.ordering, every vertex array in the scene's own numbering.
template <class S>
std::unique_ptr<OrderedSimulator<S>> make_simulator(const Scene& scene, const RunOptions& run = {});

// "pool x2, auto, adaptive", "cuda (NVIDIA H100 ...)" and the like
// (executor: make_run_executor's).
std::string describe(const RunOptions& run, const Executor* executor);

}  // namespace edgefem
