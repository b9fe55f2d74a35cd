#include "edgefem/core/retain_freed_memory.hpp"

#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace edgefem {

bool retain_freed_memory() {
#if defined(__GLIBC__)
    if (const char* t = std::getenv("GLIBC_TUNABLES"); t != nullptr && std::strstr(t, "glibc.malloc.") != nullptr)
        return false;
    constexpr int kTrim = 512 << 20;  // bytes
    constexpr int kMmap = 32 << 20;   // glibc's largest mmap threshold on 64-bit systems
    return mallopt(M_TRIM_THRESHOLD, kTrim) == 1 && mallopt(M_MMAP_THRESHOLD, kMmap) == 1;
#else
    return false;
#endif
}

}  // namespace edgefem
