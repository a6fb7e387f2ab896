// Checks the command lines make before any work: whole numbers written as a user would
// (`--leaves 1e4`), output files that can be written (before a solve, not after it), the
// memory a job needs against what the machine has. Header-only, for leaflux and
// leaflux-grow alike; the errors name the option.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace leaflux {

// A transform for integer options: "10000", "1e4" and "1.0e+4" read as 10000; "1.5",
// "1e40" and "ten" are refused with a sentence that says what is wanted.
inline CLI::Validator WholeNumber() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            char* end = nullptr;
            errno = 0;
            const double value = std::strtod(text.c_str(), &end);
            if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE ||
                !std::isfinite(value)) {
                return "expects a whole number (such as 10000 or 1e4), got '" + text + "'";
            }
            if (value != std::floor(value) || std::abs(value) > 9.0e15) {
                return "expects a whole number, got " + text +
                       " (not a whole number, or too "
                       "large)";
            }
            text = std::to_string(static_cast<long long>(value));
            return "";
        },
        "", "WholeNumber");
}

// A path a run will write: its folder is created, and the file is opened for writing
// without truncating it (a file that did not exist is removed again), so that a run that
// cannot write its results fails before it starts. Throws std::invalid_argument naming the
// option and the path.
inline void CheckWritable(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    const auto fail = [&](const std::string& why) {
        throw std::invalid_argument(option + " " + path + ": cannot be written: " + why);
    };
    if (path.empty()) fail("the path is empty");
    std::error_code error;
    if (fs::is_directory(path, error)) fail("it is a folder; give a file name");
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty()) {
        fs::create_directories(parent, error);
        if (error) fail("its folder cannot be made (" + error.message() + ")");
    }
    const bool existed = fs::exists(path, error);
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) fail(std::strerror(errno));
    ::close(fd);
    if (!existed) ::unlink(path.c_str());
}

// Memory the machine can give a new job (bytes): MemAvailable of /proc/meminfo, or 0 when
// unknown.
inline std::uint64_t AvailableMemoryBytes() {
    std::ifstream meminfo("/proc/meminfo");
    std::string key;
    std::uint64_t kib = 0;
    std::string unit;
    while (meminfo >> key >> kib >> unit) {
        if (key == "MemAvailable:") return kib * 1024;
    }
    return 0;
}

}  // namespace leaflux
