// Keeps the memory a process frees for its own reuse rather than handing it
// back to the system at once. A program that frees and allocates large
// buffers again and again (the AMG's refresh: about 4.4 MB on bunny-4k,
// each refresh) otherwise writes fresh pages every time, and each costs a
// page fault: ~10 us on the development VM, two thirds of a bunny-4k refresh
// there (docs/parallel.md, "Set-up on a VM: page faults"). With glibc it
// raises malloc's trim threshold (freed memory at the top of the heap is
// kept up to 512 MiB) and its mmap threshold (blocks up to 32 MiB come from
// the heap, so they are kept too; larger ones are still returned when
// freed). The peak memory does not change; the process keeps its peak.
//
// Process-wide: for a program's main() (the edgefem program and the solver
// benchmark call it), not for a library to call on its user's behalf.
// Without glibc, or where GLIBC_TUNABLES already sets a glibc.malloc
// tunable (the user's choice stands), it does nothing.
#pragma once

namespace edgefem {

// Returns whether it changed malloc's settings.
bool retain_freed_memory();

}  // namespace edgefem
