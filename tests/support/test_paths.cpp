#include "tests/support/test_paths.h"

#include <filesystem>

#include <unistd.h>

namespace lobe::test {

std::string source_path(const std::string& rel) { return std::string(LOBE_SOURCE_DIR) + "/" + rel; }
std::string shared_path(const std::string& rel) { return std::string(LOBE_SHARED_DIR) + "/" + rel; }

std::string temp_dir(const std::string& name)
{
    auto dir = std::filesystem::temp_directory_path() /
               ("lobesketch-test-" + std::to_string(::getpid()) + "-" + name);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

std::string cli_path()
{
#ifdef LOBE_CLI_PATH
    return LOBE_CLI_PATH;
#else
    return "lobesketch";
#endif
}

} // namespace lobe::test
