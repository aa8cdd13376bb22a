#include "tests/support/cli_run.h"

#include <array>
#include <cstdio>

#include <sys/wait.h>

#include "tests/support/test_paths.h"

namespace lobe::test {

CliRun run_cli(const std::string& args, const std::string& env)
{
    CliRun r;
    const std::string cmd = env + (env.empty() ? "" : " ") + cli_path() + " " + args + " 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf;
    while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) r.out.append(buf.data(), n);
    const int status = ::pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return r;
}

} // namespace lobe::test
