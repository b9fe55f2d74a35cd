// retain_freed_memory(): after it, memory a program frees and allocates
// again is reused without a page fault (glibc's defaults trim it and fault
// it in again every time: the AMG's refreshes paid ~1,100 faults each on
// bunny-4k); a GLIBC_TUNABLES malloc setting of the user's is left alone.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "edgefem/core/retain_freed_memory.hpp"

namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kOwnAllocator = true;  // the sanitizer's allocator replaces glibc's malloc
#else
constexpr bool kOwnAllocator = false;
#endif

long minor_faults() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_minflt;
}

// The page faults of one round as a refresh does it: eight 1 MiB buffers
// allocated and written, then freed (2,048 pages of 4 KiB).
long round_faults() {
    const long before = minor_faults();
    std::vector<std::unique_ptr<char[]>> blocks;
    for (int i = 0; i < 8; ++i) {
        blocks.emplace_back(new char[1 << 20]);
        std::memset(blocks.back().get(), i + 1, 1 << 20);
    }
    long sum = 0;
    for (const auto& b : blocks) sum += b[12345];
    blocks.clear();
    EXPECT_EQ(sum, 36);  // the writes happened
    return minor_faults() - before;
}

}  // namespace

TEST(RetainFreedMemory, LeavesAUsersMallocTunablesAlone) {
    ::setenv("GLIBC_TUNABLES", "glibc.malloc.check=0", 1);
    EXPECT_FALSE(edgefem::retain_freed_memory());
    ::unsetenv("GLIBC_TUNABLES");
}

TEST(RetainFreedMemory, LaterRoundsReuseTheFirstRoundsPages) {
#if !defined(__GLIBC__)
    GTEST_SKIP() << "glibc only";
#endif
    if (kOwnAllocator) GTEST_SKIP() << "a sanitizer's allocator";
    ::unsetenv("GLIBC_TUNABLES");
    round_faults();
    for (int r = 0; r < 3; ++r) EXPECT_GT(round_faults(), 1500) << "glibc's defaults, round " << r;
    ASSERT_TRUE(edgefem::retain_freed_memory());
    round_faults();
    for (int r = 0; r < 3; ++r) EXPECT_LT(round_faults(), 64) << "kept for reuse, round " << r;
}
