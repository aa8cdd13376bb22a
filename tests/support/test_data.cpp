#include "tests/support/test_data.h"

#include <filesystem>
#include <system_error>

#include <gtest/gtest.h>

#include "tests/support/test_paths.h"

namespace lobe::test {

bool require_data(const std::string& path, const char* file, int line)
{
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) return true;
    // The message alone, without the "Failed" line GTEST_FAIL_AT() puts before it.
    const std::string message = "missing test data: " + path;
    GTEST_MESSAGE_AT_(file, line, message.c_str(), ::testing::TestPartResult::kFatalFailure);
    return false;
}

std::string source_data(const std::string& rel, const char* file, int line)
{
    std::string path = source_path(rel);
    return require_data(path, file, line) ? path : std::string();
}

std::string shared_data(const std::string& rel, const char* file, int line)
{
    std::string path = shared_path(rel);
    return require_data(path, file, line) ? path : std::string();
}

} // namespace lobe::test
