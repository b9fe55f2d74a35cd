// What a first touch of fresh memory costs: the time per 4 KiB page to
// write one byte into each page of a fresh 64 MiB block, three rounds (the
// block freed between them, so each round faults again). On a VM a page
// fault can cost tens of times what it costs on bare metal; set-up (mesh,
// topology, operators, the AMG's first build) touches its memory once, and
// docs/parallel.md, "Set-up on a VM: page faults", says what that costs
// and what helps.
//
// usage: edgefem_page_fault_probe [MIB in [1, 4096]]   (default 64)
#include <sys/mman.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
    char* end = nullptr;
    const long mib = argc > 1 ? std::strtol(argv[1], &end, 10) : 64;
    if (argc > 2 || (argc > 1 && (end == argv[1] || *end != '\0')) || mib < 1 || mib > 4096) {
        std::fprintf(stderr, "usage: edgefem_page_fault_probe [MIB in [1, 4096]]\n");
        return 2;
    }
    const std::size_t bytes = std::size_t(mib) << 20, page = 4096;
    for (int round = 0; round < 3; ++round) {
        // mmap, not malloc: fresh pages every round, whatever the allocator keeps
        void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) {
            std::fprintf(stderr, "edgefem_page_fault_probe: mmap of %ld MiB failed\n", mib);
            return 3;
        }
        auto* c = static_cast<volatile char*>(p);
        const auto t0 = std::chrono::steady_clock::now();
        for (std::size_t i = 0; i < bytes; i += page) c[i] = 1;
        const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
        std::printf("round %d: %ld MiB, %.2f us per 4 KiB page\n", round + 1, mib, us / double(bytes / page));
        munmap(p, bytes);
    }
}
