// A file of the given text in the tests' temporary folder, for readers that take a path.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace leaflux::testing {

inline std::string WriteTempFile(const std::string& name, const std::string& text) {
    const std::string path = ::testing::TempDir() + name;
    std::ofstream(path) << text;
    return path;
}

}  // namespace leaflux::testing
