// A file that appears whole or not at all. The text goes to a temporary file
// in the target's folder, created exclusively (never through a symbolic link
// planted at its name); commit() renames it over the target in one step, so
// a reader, a kill or a full disk sees the old file or the new one, never a
// truncated one, and a symbolic link at the target's name is replaced, not
// followed. Without commit() (an error, an exception) the temporary file is
// removed and the target is untouched. (Not fsync'ed: a power failure may
// still lose the new file's data; a crash of this process does not.)
#pragma once

#include <string>
#include <string_view>

namespace edgefem {

class OutputFile {
public:
    // Throws IoError naming `path` when the temporary file cannot be created
    // (missing or unwritable folder) or `path` is a folder.
    explicit OutputFile(std::string path);
    ~OutputFile();
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    // Buffered; throws IoError naming the target on a failed write (disk
    // full, file size limit, ...).
    void write(std::string_view data);
    // Writes what is buffered and renames the file over the target; throws
    // IoError on failure (the temporary file is removed then).
    void commit();
    const std::string& path() const { return path_; }

private:
    void flush();
    [[noreturn]] void fail(const std::string& what, int error);

    std::string path_, tmp_;
    int fd_ = -1;
    std::string buffer_;
};

// Writes `text` to `path` through an OutputFile.
void write_file_atomically(const std::string& path, std::string_view text);

}  // namespace edgefem
