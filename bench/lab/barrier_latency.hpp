// What one phase boundary (a barrier with nothing to wait for) costs on an
// executor: for_uniform_phases over `phases` phases of one empty chunk per
// thread, median of `repetitions` timings, per phase. On a VM the answer
// depends on where the host has put the threads (docs/parallel.md, "Thread
// placement on a VM": ~0.27 against ~0.46 us at 2 threads on one
// development VM, 1.2-1.6 us on another), and so do the
// multi-threaded timings of small kernels, so `edgefem bench` prints it
// before and after its timed calls.
#pragma once

#include "edgefem/core/executor.hpp"

namespace edgefem {

// Microseconds per phase. Throws InvalidArgument unless phases >= 1 and
// repetitions >= 1.
double phase_barrier_us(const Executor& ex, int phases = 2000, int repetitions = 5);

}  // namespace edgefem
