// The executors the tests run over. Under ThreadSanitizer oneTBB is left
// out: Debian's libtbb is not built with TSan, which then cannot see its
// task hand-offs and reports every parallel_for as a race (docs/testing.md,
// "AddressSanitizer + UBSan, ThreadSanitizer"); OpenMP stays, checked
// through LLVM's libomp and its Archer tool.
#pragma once

#include <vector>

#include "edgefem/parallel/executors.hpp"

namespace edgefem::test {

#if defined(__SANITIZE_THREAD__)
inline constexpr bool kThreadSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
inline constexpr bool kThreadSanitizer = true;
#else
inline constexpr bool kThreadSanitizer = false;
#endif
#else
inline constexpr bool kThreadSanitizer = false;
#endif

// OpenMP, oneTBB (not under TSan) and the pool.
inline std::vector<ExecutorKind> threaded_executor_kinds() {
    if (kThreadSanitizer) return {ExecutorKind::OpenMP, ExecutorKind::Pool};
    return {ExecutorKind::OpenMP, ExecutorKind::TBB, ExecutorKind::Pool};
}

// Serial and the threaded ones.
inline std::vector<ExecutorKind> executor_kinds() {
    std::vector<ExecutorKind> kinds{ExecutorKind::Serial};
    for (ExecutorKind k : threaded_executor_kinds()) kinds.push_back(k);
    return kinds;
}

}  // namespace edgefem::test
