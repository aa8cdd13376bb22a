#pragma once
// Running the built lobesketch executable from tests, as a user does.
#include <string>

namespace lobe::test {

struct CliRun {
    int code = -1;   ///< exit status (128 + signal when killed)
    std::string out; ///< stdout and stderr together
};

/// Runs `lobesketch ARGS`, with `env` ("NAME=value …") put before it when given.
CliRun run_cli(const std::string& args, const std::string& env = "");

} // namespace lobe::test
