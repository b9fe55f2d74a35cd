#include "edgefem/core/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "edgefem/core/error.hpp"

namespace edgefem {

namespace {

std::atomic<unsigned> g_counter{0};

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
    struct stat st;
    if (::stat(path_.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
        throw IoError("cannot write '" + path_ + "': it is a folder", path_);
    const std::filesystem::path target(path_);
    const std::string name = target.filename().string();
    const std::filesystem::path dir = target.parent_path();
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::string tmp_name =
            "." + name + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(g_counter++);
        tmp_ = (dir / tmp_name).string();
        // O_EXCL: never an existing file, nor a symbolic link planted at the name.
        fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd_ >= 0) return;
        if (errno != EEXIST) break;
    }
    const int error = errno;
    tmp_.clear();
    throw IoError("cannot write '" + path_ + "': " + std::strerror(error), path_);
}

OutputFile::~OutputFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!tmp_.empty()) ::unlink(tmp_.c_str());
}

void OutputFile::fail(const std::string& what, int error) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!tmp_.empty()) ::unlink(tmp_.c_str());
    tmp_.clear();
    buffer_.clear();
    throw IoError(what + " '" + path_ + "': " + std::strerror(error), path_);
}

void OutputFile::write(std::string_view data) {
    if (fd_ < 0) throw IoError("cannot write '" + path_ + "': the file is already closed", path_);
    buffer_.append(data);
    if (buffer_.size() >= (1u << 20)) flush();
}

void OutputFile::flush() {
    const char* p = buffer_.data();
    std::size_t left = buffer_.size();
    while (left > 0) {
        const ssize_t n = ::write(fd_, p, left);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail("error while writing", errno);
        }
        p += n;
        left -= static_cast<std::size_t>(n);
    }
    buffer_.clear();
}

void OutputFile::commit() {
    if (fd_ < 0) throw IoError("cannot write '" + path_ + "': the file is already closed", path_);
    flush();
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail("error while writing", errno);
    if (::rename(tmp_.c_str(), path_.c_str()) != 0) fail("cannot replace", errno);
    tmp_.clear();
}

void write_file_atomically(const std::string& path, std::string_view text) {
    OutputFile f(path);
    f.write(text);
    f.commit();
}

}  // namespace edgefem
