#include "app/full_cli.h"

#include <vector>

#include "app/cli_main.h"
#include "app/level_thumbnail.h"
#include "app/light_commands.h"

namespace lucent::app {

int run_full_cli(int argc, char** argv) {
    set_analyze_thumbnail_maker(level_thumbnail_png);
    std::vector<Registration> subcommands = {
        register_info,    register_render, register_run,   register_explore,
        register_stimuli, register_serve,  register_bench, register_truth};
    for (const LightCommand& light : light_commands())
        subcommands.push_back(light.registration);
    return run_cli(argc, argv, subcommands);
}

}  // namespace lucent::app
