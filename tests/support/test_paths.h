#pragma once
// Paths to test data. ../shared is optional: tests that need it skip with a reason.
#include <gtest/gtest.h>

#include <filesystem>

namespace lucent::test {

inline std::filesystem::path shared_dir() { return LUCENT_SHARED_DIR; }
inline std::filesystem::path source_dir() { return LUCENT_SOURCE_DIR; }
inline std::filesystem::path binary_dir() { return LUCENT_BINARY_DIR; }

// Fresh empty directory under the build tree for one test's output files:
// test-scratch/<name>/<Suite.Test>. ctest runs each test in its own process, in parallel,
// so two tests of one fixture must not share (and wipe) a directory.
inline std::filesystem::path scratch_dir(const std::string& name) {
    auto dir = binary_dir() / "test-scratch" / name;
    if (const auto* test = ::testing::UnitTest::GetInstance()->current_test_info()) {
        std::string id = std::string(test->test_suite_name()) + "." + test->name();
        for (char& c : id)
            if (c == '/') c = '_';  // parameterised names: Prefix/Suite.Test/Param
        dir /= id;
    }
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace lucent::test

// Skips the current test when ../shared (or a file in it) is absent.
#define LUCENT_REQUIRE_SHARED(relative)                                                 \
    do {                                                                                \
        if (!std::filesystem::exists(::lucent::test::shared_dir() / (relative)))        \
            GTEST_SKIP() << "test data " << (::lucent::test::shared_dir() / (relative)) \
                         << " is absent (../shared is optional)";                       \
    } while (0)
