#pragma once
// Where tests find the project's recordings and the shared reference data.
#include <string>

namespace lobe::test {
std::string source_path(const std::string& rel); ///< relative to the project root
std::string shared_path(const std::string& rel); ///< relative to ../shared
std::string temp_dir(const std::string& name);   ///< a fresh empty folder for one test
std::string cli_path();                          ///< the built lobesketch executable
} // namespace lobe::test
