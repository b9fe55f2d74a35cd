#include "text_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <system_error>

#include "edgefem/core/error.hpp"

namespace edgefem::detail {

namespace {
bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
}  // namespace

std::string_view LineTokens::next() {
    std::size_t i = 0;
    while (i < rest_.size() && is_space(rest_[i])) ++i;
    std::size_t j = i;
    while (j < rest_.size() && !is_space(rest_[j])) ++j;
    const std::string_view token = rest_.substr(i, j - i);
    rest_.remove_prefix(j);
    return token;
}

bool LineTokens::empty() const {
    return std::all_of(rest_.begin(), rest_.end(), is_space);
}

std::size_t LineTokens::count() const {
    LineTokens copy = *this;
    std::size_t n = 0;
    while (!copy.next().empty()) ++n;
    return n;
}

TextReader::TextReader(std::string path, char comment, const std::string& kind)
    : path_(std::move(path)), comment_(comment) {
    std::error_code ec;
    const auto status = std::filesystem::status(path_, ec);
    if (std::filesystem::is_directory(status))
        throw MeshError("is a directory, not a " + kind, path_);
    // A device or a pipe (/dev/zero) may never end; the whole file is loaded.
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        throw MeshError("not a regular file", path_);
    std::FILE* f = std::fopen(path_.c_str(), "rb");
    if (!f) throw MeshError(std::string("cannot open file: ") + std::strerror(errno), path_);
    const auto size = std::filesystem::file_size(path_, ec);
    if (!ec) data_.reserve(static_cast<std::size_t>(size));
    char buffer[1 << 16];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) data_.append(buffer, n);
    const bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) throw MeshError("error while reading the file", path_);
}

bool TextReader::scan(std::size_t& pos, std::int64_t& line_no, std::string_view& line) const {
    while (pos < data_.size()) {
        std::size_t end = data_.find('\n', pos);
        if (end == std::string::npos) end = data_.size();
        std::string_view l(data_.data() + pos, end - pos);
        pos = std::min(end + 1, data_.size());
        ++line_no;
        if (comment_ != '\0') {
            const std::size_t c = l.find(comment_);
            if (c != std::string_view::npos) l = l.substr(0, c);
        }
        while (!l.empty() && is_space(l.front())) l.remove_prefix(1);
        while (!l.empty() && is_space(l.back())) l.remove_suffix(1);
        if (!l.empty()) {
            line = l;
            return true;
        }
    }
    return false;
}

bool TextReader::next_line() {
    if (scan(pos_, line_no_, line_)) return true;
    line_ = {};
    return false;
}

void TextReader::require_line(const std::string& what) {
    if (next_line()) return;
    if (data_.empty()) fail("file is empty");
    fail("unexpected end of file (truncated?): expected " + what);
}

void TextReader::fail(const std::string& message, std::int64_t element) const {
    fail_at(line_no_, message, element);
}

void TextReader::fail_at(std::int64_t line, const std::string& message,
                         std::int64_t element) const {
    throw MeshError(message, path_, line, element);
}

std::string_view TextReader::need(LineTokens& tokens, const std::string& what) const {
    const std::string_view t = tokens.next();
    if (t.empty()) fail("missing " + what);
    return t;
}

void TextReader::expect_end(LineTokens& tokens, const std::string& what) const {
    const std::string_view t = tokens.next();
    if (!t.empty()) fail("unexpected '" + quote(t) + "' after " + what);
}

std::int64_t TextReader::parse_int(std::string_view token, const std::string& what) const {
    const char* b = token.data();
    const char* e = b + token.size();
    if (b != e && *b == '+' && e - b > 1 && b[1] != '-') ++b;  // from_chars rejects '+'
    std::int64_t v = 0;
    const auto [p, ec] = std::from_chars(b, e, v);
    if (ec == std::errc::result_out_of_range)
        fail(what + " '" + quote(token) + "' is out of the 64-bit integer range");
    if (ec != std::errc() || p != e || b == e)
        fail("expected an integer for " + what + ", got '" + quote(token) + "'");
    return v;
}

double TextReader::parse_double(std::string_view token, const std::string& what) const {
    const char* b = token.data();
    const char* e = b + token.size();
    if (b != e && *b == '+' && e - b > 1 && b[1] != '-') ++b;
    double v = 0;
    const auto [p, ec] = std::from_chars(b, e, v, std::chars_format::general);
    if (ec == std::errc::result_out_of_range)
        fail(what + " '" + quote(token) + "' is out of the double range");
    if (ec != std::errc() || p != e || b == e)
        fail("expected a number for " + what + ", got '" + quote(token) + "'");
    return v;
}

index_t TextReader::check_count(std::int64_t count, int min_tokens, const std::string& what) const {
    if (count < 0) fail("negative " + what + " count " + std::to_string(count));
    if (count > std::numeric_limits<index_t>::max())
        fail(what + " count " + std::to_string(count) +
             " exceeds the supported maximum of 2^31-1");
    // Each item needs min_tokens tokens, each at least 1 byte plus 1 separator
    // (the very last one may lack its newline). When the bytes fall short but
    // enough lines are left, some item line is short: the item parser names
    // it precisely ("missing z coordinate"), so only a count past the lines
    // left is blamed here. Either way the count is bounded by the file size.
    const std::uint64_t rest = data_.size() - pos_;
    const std::uint64_t need = static_cast<std::uint64_t>(count) * 2u * min_tokens;
    if (need > rest + 1 && !has_lines(count))
        fail(what + " count " + std::to_string(count) + " is more than the rest of the file (" +
             std::to_string(rest) + " bytes) can hold: the count is wrong or the file truncated");
    return static_cast<index_t>(count);
}

bool TextReader::has_lines(std::int64_t n) const {
    std::size_t pos = pos_;
    std::int64_t line_no = line_no_;
    std::string_view line;
    for (std::int64_t i = 0; i < n; ++i)
        if (!scan(pos, line_no, line)) return false;
    return true;
}

std::string quote(std::string_view token) {
    std::string out;
    for (const char c : token.substr(0, 40))
        out += (static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f) ? c
                                                                                                : '?';
    if (token.size() > 40) out += "...";
    return out;
}

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; };
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

std::string item_label(const char* kind, std::int64_t index, std::int64_t file_id) {
    std::string out = std::string(kind) + " " + std::to_string(index);
    if (file_id != index) out += " (numbered " + std::to_string(file_id) + " in the file)";
    return out;
}

void check_finite(const TextReader& reader, const double* xyz, index_t vertex,
                  std::int64_t file_id) {
    if (std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2])) return;
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, " has a non-finite coordinate (%g, %g, %g)", xyz[0],
                  xyz[1], xyz[2]);
    reader.fail(item_label("vertex", vertex, file_id) + buffer, vertex);
}

std::vector<index_t> resolve_indices(const std::string& file, const std::vector<std::int64_t>& raw, int per_item,
                                     const char* kind, std::int64_t base, index_t nv,
                                     const std::vector<std::int64_t>& line, const std::vector<std::int64_t>& id) {
    std::vector<index_t> out(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) {
        const std::int64_t v = raw[i] - base;
        if (raw[i] >= base && v < nv) {
            out[i] = static_cast<index_t>(v);
            continue;
        }
        const std::size_t t = i / per_item;
        const std::string range =
            nv == 0 ? "the file has no vertices"
                    : "vertices are numbered " + std::to_string(base) + ".." +
                          std::to_string(base + nv - 1);
        const std::int64_t file_id = t < id.size() ? id[t] : static_cast<std::int64_t>(t);
        throw MeshError(item_label(kind, static_cast<std::int64_t>(t), file_id) +
                            ": vertex index " + std::to_string(raw[i]) + " is out of range (" +
                            range + ")",
                        file, line[t], static_cast<std::int64_t>(t));
    }
    return out;
}

std::vector<index_t> resolve_tets(const std::string& file, const std::vector<std::int64_t>& raw,
                                  std::int64_t base, index_t nv,
                                  const std::vector<std::int64_t>& tet_line,
                                  const std::vector<std::int64_t>& tet_id) {
    return resolve_indices(file, raw, 4, "tet", base, nv, tet_line, tet_id);
}

int region_from_attribute(const TextReader& reader, double value) {
    char shown[32];
    std::snprintf(shown, sizeof shown, "%.17g", value);
    if (!std::isfinite(value) || std::fabs(value) > std::numeric_limits<int>::max())
        reader.fail(std::string("region attribute ") + shown + " is not a usable region id");
    // -2.7 used to become region -3: a region id is an integer, up to the
    // round-off of a writer that stored it as a float (0.9999999 is 1).
    const double rounded = std::round(value);
    if (std::fabs(value - rounded) > 1e-6 * std::max(1.0, std::fabs(value)))
        reader.fail(std::string("region attribute ") + shown + " is not an integer (region ids are integers)");
    return static_cast<int>(rounded);
}

std::string ascii_lower(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return out;
}

std::string ascii_upper(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
    return out;
}

}  // namespace edgefem::detail
