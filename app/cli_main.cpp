#include "app/cli.h"

#include <CLI/CLI.hpp>

namespace lobe {

int run_cli(int argc, char** argv)
{
    CLI::App app{"Lobesketch: sketch trees with your hands"};
    app.require_subcommand(1);
    CLI11_PARSE(app, argc, argv);
    return kExitOk;
}

} // namespace lobe
