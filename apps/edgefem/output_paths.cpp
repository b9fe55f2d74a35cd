#include "output_paths.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "edgefem/core/error.hpp"

namespace edgefem::cli {

namespace fs = std::filesystem;

void check_scene_output_dir(const std::string& dir, const std::string& scene) {
    const auto refuse = [&](const std::string& why) {
        throw InvalidArgument(scene + ": \"output.dir\": '" + dir + "' " + why +
                              ": a scene writes only below the folder edgefem runs in; give another folder with --out");
    };
    const fs::path p(dir);
    if (p.is_absolute()) refuse("is an absolute path");
    const fs::path normal = p.lexically_normal();
    if (!normal.empty() && *normal.begin() == "..") refuse("leads outside the current folder");
    std::error_code ec;
    const fs::path cwd = fs::weakly_canonical(fs::current_path(ec), ec);
    const fs::path real = fs::weakly_canonical(fs::absolute(p, ec), ec);
    if (ec) return;  // nothing to resolve yet: the lexical check holds
    const fs::path rel = real.lexically_relative(cwd);
    if (rel.empty() || *rel.begin() == "..") refuse("leads outside the current folder (through a symbolic link)");
}

void make_output_dir(const std::string& dir, const std::string& option) {
    std::error_code ec;
    const auto st = fs::status(dir, ec);
    if (fs::exists(st) && !fs::is_directory(st))
        throw InvalidArgument(option + ": '" + dir + "' exists and is not a folder (frames go into a folder)");
    fs::create_directories(dir, ec);
    if (ec) throw IoError("cannot create the output folder '" + dir + "': " + ec.message(), dir);
}

void check_replaceable(const std::string& path, std::string_view signature) {
    struct stat st;
    if (::lstat(path.c_str(), &st) != 0) {
        if (errno == ENOENT) return;
        throw IoError("cannot check '" + path + "': " + std::strerror(errno), path);
    }
    if (S_ISLNK(st.st_mode))
        throw IoError("refusing to write '" + path + "': it is a symbolic link (edgefem never writes through one; "
                      "remove it or choose another output)",
                      path);
    if (!S_ISREG(st.st_mode))
        throw IoError("refusing to write '" + path + "': it exists and is not a regular file", path);
    if (signature.empty()) return;
    std::string head(signature.size(), '\0');
    const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    ssize_t got = 0;
    if (fd >= 0) {
        got = ::read(fd, head.data(), head.size());
        ::close(fd);
    }
    if (got != static_cast<ssize_t>(head.size()) || head != signature)
        throw IoError("refusing to overwrite '" + path + "': it is not a file of this output (edgefem replaces only "
                      "the frames and series it wrote); remove it or choose another output folder",
                      path);
}

}  // namespace edgefem::cli
