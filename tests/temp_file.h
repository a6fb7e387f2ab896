// Files of the running test's own in the tests' temporary folder, for readers that take a
// path: ctest runs the tests side by side, each in a process of its own, and two tests
// writing one name read each other's files.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace leaflux::testing {

// `name` in the temporary folder, prefixed with the running test's suite and name.
inline std::string TempPath(const std::string& name) {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string prefix =
        test ? std::string(test->test_suite_name()) + "." + test->name() + "." : std::string();
    std::replace(prefix.begin(), prefix.end(), '/', '_');  // parameterised tests' names
    return ::testing::TempDir() + prefix + name;
}

// A file of the given text at TempPath(name); returns its path.
inline std::string WriteTempFile(const std::string& name, const std::string& text) {
    const std::string path = TempPath(name);
    std::ofstream(path) << text;
    return path;
}

}  // namespace leaflux::testing
