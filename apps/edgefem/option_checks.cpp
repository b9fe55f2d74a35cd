#include "option_checks.hpp"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "common.hpp"
#include "edgefem/core/error.hpp"

namespace edgefem::cli {

CLI::Validator int_in_range(long long min, long long max) {
    const bool bounded = max != std::numeric_limits<long long>::max();
    const std::string want = bounded ? "expected an integer from " + std::to_string(min) + " to " + std::to_string(max)
                                     : "expected an integer >= " + std::to_string(min);
    return CLI::Validator(
        [min, max, want](std::string& s) {
            long long v = 0;
            const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
            if (ec != std::errc() || end != s.data() + s.size() || v < min || v > max)
                return want + ", got '" + s + "'";
            return std::string();
        },
        // The name --help shows after the type ("INT:POSITIVE").
        bounded    ? "[" + std::to_string(min) + " - " + std::to_string(max) + "]"
        : min == 0 ? "NONNEGATIVE"
        : min == 1 ? "POSITIVE"
                   : ">= " + std::to_string(min));
}

CLI::Validator seconds_at_most(double max) {
    const std::string want = "expected a number of seconds > 0 and <= " + fmt(max, 6);
    return CLI::Validator(
        [max, want](std::string& s) {
            double v = 0;
            const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
            // !(v <= max) also catches NaN.
            if (ec != std::errc() || end != s.data() + s.size() || !(v > 0) || !(v <= max))
                return want + ", got '" + s + "'";
            return std::string();
        },
        "POSITIVE <= " + fmt(max, 6));
}

CLI::Validator non_empty_path() {
    return CLI::Validator([](std::string& s) { return s.empty() ? std::string("empty path") : std::string(); },
                          "");
}

void reject_empty_numbers(CLI::App& app) {
    for (CLI::Option* opt : app.get_options()) {
        // The type name is followed by the checks' names ("INT:NONNEGATIVE").
        const std::string full = opt->get_type_name(), type = full.substr(0, full.find(':'));
        if (type == "INT" || type == "UINT" || type == "FLOAT" || type == "NUMBER")
            // transform() puts the check first, ahead of range checks that
            // would complain about "" in their own words.
            opt->transform(CLI::Validator(
                [](std::string& s) { return s.empty() ? std::string("empty value") : std::string(); }, ""));
    }
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) reject_empty_numbers(*sub);
}

void check_writable(const std::string& option, const std::string& path) {
    namespace fs = std::filesystem;
    if (path.empty()) throw InvalidArgument(option + ": empty path");
    std::error_code ec;
    const fs::path p(path);
    if (fs::is_directory(p, ec)) throw InvalidArgument(option + ": " + path + " is a folder, not a file");
    if (fs::exists(p, ec)) {
        if (::access(path.c_str(), W_OK) != 0)
            throw InvalidArgument(option + ": cannot write " + path + ": " + std::strerror(errno));
        return;
    }
    const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    if (!fs::is_directory(dir, ec))
        throw InvalidArgument(option + ": cannot write " + path + ": no folder " + dir.string());
    if (::access(dir.c_str(), W_OK) != 0)
        throw InvalidArgument(option + ": cannot write " + path + ": folder " + dir.string() + ": " +
                              std::strerror(errno));
}

}  // namespace edgefem::cli
