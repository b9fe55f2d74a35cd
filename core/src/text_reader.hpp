// Line-oriented reading of text mesh files, shared by the readers (private to
// core/src). The whole file is loaded once, then served line by line with the
// 1-based line number kept for error messages; numbers are parsed with
// std::from_chars, so parsing is locale-independent and never reads past a
// token. Every failure throws MeshError naming the file and the line.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "edgefem/core/mesh.hpp"

namespace edgefem::detail {

// Whitespace-separated tokens of one line.
class LineTokens {
public:
    explicit LineTokens(std::string_view line) : rest_(line) {}
    // The next token, or an empty view when none is left.
    std::string_view next();
    bool empty() const;
    // How many tokens are left (does not consume them).
    std::size_t count() const;

private:
    std::string_view rest_;
};

class TextReader {
public:
    // Loads `path`; `comment` starts a comment running to the end of the line
    // ('\0': the format has no comments). Throws MeshError when the file
    // cannot be read or is not a regular file; `kind` names what the file
    // should be ("mesh file") in those messages.
    TextReader(std::string path, char comment, const std::string& kind = "mesh file");

    const std::string& path() const { return path_; }
    bool file_empty() const { return data_.empty(); }

    // Moves to the next line that is not blank once its comment is stripped;
    // false at the end of the file.
    bool next_line();
    // next_line(), failing with "unexpected end of file: expected <what>"
    // (or "file is empty") at the end of the file.
    void require_line(const std::string& what);
    std::string_view line() const { return line_; }
    std::int64_t line_no() const { return line_no_; }
    LineTokens tokens() const { return LineTokens(line_); }

    [[noreturn]] void fail(const std::string& message, std::int64_t element = -1) const;
    [[noreturn]] void fail_at(std::int64_t line, const std::string& message,
                              std::int64_t element = -1) const;

    // The next token of `tokens`, failing with "missing <what>" when none is left.
    std::string_view need(LineTokens& tokens, const std::string& what) const;
    // Fails unless `tokens` is used up ("unexpected '<tok>' after <what>").
    void expect_end(LineTokens& tokens, const std::string& what) const;
    std::int64_t parse_int(std::string_view token, const std::string& what) const;
    // Accepts "nan" and "inf" (callers reject them with a clearer message).
    double parse_double(std::string_view token, const std::string& what) const;
    std::int64_t next_int(LineTokens& tokens, const std::string& what) const {
        return parse_int(need(tokens, what), what);
    }
    double next_double(LineTokens& tokens, const std::string& what) const {
        return parse_double(need(tokens, what), what);
    }

    // Validates a count read from a header before anything is allocated for
    // it: it must be non-negative, fit index_t, and the rest of the file must
    // be long enough for `count` items of at least `min_tokens` tokens each,
    // or at least hold `count` more lines (then a short item line is left
    // for the item parser to report). A corrupt count cannot make us reserve
    // more than the file's size in items.
    index_t check_count(std::int64_t count, int min_tokens, const std::string& what) const;

private:
    // The next non-blank line (comment stripped) at or after `pos`, moving
    // `pos` and `line_no` past it; false at the end of the file.
    bool scan(std::size_t& pos, std::int64_t& line_no, std::string_view& line) const;
    // Whether `n` more non-blank lines follow the current one.
    bool has_lines(std::int64_t n) const;

    std::string path_;
    std::string data_;
    std::size_t pos_ = 0;
    std::string_view line_;
    std::int64_t line_no_ = 0;
    char comment_;
};

// A token made safe to quote in a message: at most 40 characters,
// non-printable bytes shown as '?'.
// ASCII-only case conversion for keywords (locale-independent).
std::string ascii_lower(std::string_view s);
std::string ascii_upper(std::string_view s);

std::string quote(std::string_view token);

// Case-insensitive ASCII comparison.
bool iequals(std::string_view a, std::string_view b);

// "vertex 3" or "vertex 3 (numbered 4 in the file)", as Mesh::describe_* put it.
std::string item_label(const char* kind, std::int64_t index, std::int64_t file_id);

// Fails naming the vertex when one of its coordinates is NaN or infinite.
void check_finite(const TextReader& reader, const double* xyz, index_t vertex,
                  std::int64_t file_id);

// Converts the tets' file vertex numbers (`raw`, 4 per tet, numbered from
// `base`) to 0-based indices into `nv` vertices; an out-of-range number fails
// at the tet's line, naming the tet and the number.
std::vector<index_t> resolve_tets(const std::string& file, const std::vector<std::int64_t>& raw,
                                  std::int64_t base, index_t nv,
                                  const std::vector<std::int64_t>& tet_line,
                                  const std::vector<std::int64_t>& tet_id);

// The same for any item of `per_item` vertices ("triangle"); `id` may be
// empty (the items are then numbered by their index).
std::vector<index_t> resolve_indices(const std::string& file, const std::vector<std::int64_t>& raw, int per_item,
                                     const char* kind, std::int64_t base, index_t nv,
                                     const std::vector<std::int64_t>& line, const std::vector<std::int64_t>& id);

// A region attribute as an int, failing (naming the file and line) when it
// is not a finite integer (to 1e-6 relative: float round-off) that fits an int.
int region_from_attribute(const TextReader& reader, double value);

}  // namespace edgefem::detail
