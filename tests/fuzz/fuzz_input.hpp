// What the harnesses share: the readers take paths, so each input is written
// to a file in a folder of this process's own, and every edgefem::Error is
// an accepted outcome (bad input must give one, never a crash, a hang or
// another exception).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "edgefem/core/error.hpp"

namespace edgefem::fuzz {

inline const std::string& folder() {
    static const std::string dir = [] {
        const std::filesystem::path p =
            std::filesystem::temp_directory_path() / ("edgefem_fuzz_" + std::to_string(::getpid()));
        std::filesystem::create_directories(p);
        return p.string();
    }();
    return dir;
}

inline std::string write(const std::string& name, std::string_view text) {
    const std::string path = folder() + "/" + name;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
    return path;
}

// Runs `fn`; edgefem::Error is fine, anything else escapes to libFuzzer.
template <class F>
void run(F&& fn) {
    try {
        fn();
    } catch (const edgefem::Error&) {
    }
}

}  // namespace edgefem::fuzz
