#pragma once
// The command-line driver both executables share: builds the CLI11 app from a list of
// subcommand registrations, names an unknown subcommand, parses and maps exceptions to
// the shared exit codes.
#include <vector>

#include "app/commands.h"

namespace lucent::app {

using Registration = void (*)(CLI::App& app, int& exit_code);

int run_cli(int argc, char** argv, const std::vector<Registration>& subcommands);

}  // namespace lucent::app
