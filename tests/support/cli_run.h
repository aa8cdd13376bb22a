#pragma once
// Running the built lobesketch executable from tests, as a user does.
#include <cstddef>
#include <string>

namespace lobe::test {

struct CliRun {
    int code = -1;   ///< exit status (128 + signal when killed)
    std::string out; ///< stdout and stderr together
};

/// Runs `lobesketch ARGS`, with `env` ("NAME=value …") put before it when given.
CliRun run_cli(const std::string& args, const std::string& env = "");

/// The bytes of the file at `path` ("" when it cannot be read).
std::string read_file(const std::string& path);
/// Writes `text` to `path` (binary), replacing it.
void write_file(const std::string& path, const std::string& text);
/// Lines of `text`, a last line without '\n' included.
std::size_t lines_of(const std::string& text);

} // namespace lobe::test
