#include "tests/support/gltf_check.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>

#include "tests/support/test_paths.h"

namespace lobe::test {

namespace {
namespace fs = std::filesystem;

std::string read_text(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
} // namespace

::testing::AssertionResult validate_gltf(const std::string& file, nlohmann::json& report)
{
    const std::string node = LOBE_NODE_PATH;
    const std::string dir = LOBE_GLTF_VALIDATOR_DIR;
    if (node.empty() || !fs::exists(node))
        return ::testing::AssertionFailure() << "node not found (" << node
                                             << "): run scripts/setup.sh to install Node.js and the glTF validator";
    if (!fs::exists(dir + "/node_modules/gltf-validator/package.json"))
        return ::testing::AssertionFailure() << "the Khronos glTF validator is not installed in " << dir
                                             << ": run scripts/setup.sh";
    const std::string err_file = file + ".validator-stderr";
    const auto q = [](const std::string& s) { return "'" + s + "'"; };
    const std::string cmd = q(node) + " " + q(source_path("tests/support/gltf_validate.mjs")) + " --validator " + q(dir) +
                            " " + q(file) + " 2>" + q(err_file);
    FILE* p = ::popen(cmd.c_str(), "r");
    if (p == nullptr) return ::testing::AssertionFailure() << "cannot run " << cmd;
    std::string out;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = ::pclose(p);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == 2 || code < 0)
        return ::testing::AssertionFailure() << "validator run failed (" << code << "): " << read_text(err_file);
    try {
        report = nlohmann::json::parse(out);
    } catch (const std::exception& e) {
        return ::testing::AssertionFailure() << "validator output is not JSON: " << e.what() << "\n" << out;
    }
    return ::testing::AssertionSuccess();
}

std::string describe_gltf_issues(const nlohmann::json& report)
{
    std::ostringstream s;
    for (const auto& m : report["issues"]["messages"])
        s << "  [" << m.value("severity", -1) << "] " << m.value("code", "") << " " << m.value("pointer", "") << ": "
          << m.value("message", "") << "\n";
    return s.str();
}

} // namespace lobe::test
