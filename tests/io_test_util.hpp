// Small helpers shared by the mesh I/O tests (header-only, not a test itself).
#pragma once

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "test_meshes.hpp"

namespace edgefem::test {

inline std::string data_file(const std::string& name) { return test_data_dir() + "/" + name; }

inline std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The whitespace-separated numbers of a text (e.g. an ASCII DataArray).
inline std::vector<double> numbers(const std::string& text) {
    std::istringstream in(text);
    in.imbue(std::locale::classic());
    std::vector<double> out;
    double x;
    while (in >> x) out.push_back(x);
    return out;
}

inline void spit(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// The process's peak resident memory so far, in kB.
inline long peak_rss_kb() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
}

// A fresh folder under the system temp folder, removed with the object.
class TempDir {
public:
    explicit TempDir(const std::string& tag) {
        path_ = std::filesystem::temp_directory_path() /
                ("edgefem_" + tag + "_" + std::to_string(::getpid()));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    std::string path() const { return path_.string(); }

private:
    std::filesystem::path path_;
};

// Runs `fn`, expects a MeshError and checks that its message contains every
// one of `parts`; returns the message.
template <class F>
std::string expect_mesh_error(F&& fn, std::initializer_list<std::string> parts) {
    try {
        fn();
    } catch (const MeshError& e) {
        const std::string msg = e.what();
        for (const auto& part : parts)
            EXPECT_NE(msg.find(part), std::string::npos)
                << "message lacks '" << part << "': " << msg;
        return msg;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected MeshError, got another exception: " << e.what();
        return {};
    }
    ADD_FAILURE() << "expected MeshError, nothing was thrown";
    return {};
}

}  // namespace edgefem::test
