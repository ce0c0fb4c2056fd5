// lucent-full: every subcommand. Users run `lucent` (main_dispatch.cpp), which hands
// everything but the analysis subcommands to this program.
#include "app/full_cli.h"

int main(int argc, char** argv) { return lucent::app::run_full_cli(argc, argv); }
