#pragma once
// The subcommands that need no GL, images, meshes or ray casting. The `lucent` executable
// runs these itself, so an analysis never pays for loading the renderer's ~250 shared
// libraries (0.4 s of dynamic linking per process); it hands every other subcommand to
// lucent-full.
#include <string_view>
#include <vector>

#include "app/cli_main.h"

namespace lucent::app {

struct LightCommand {
    std::string_view name;
    Registration registration;
    // Options that need lucent-full after all (`analyze --images` decodes pictures).
    std::vector<std::string_view> full_options = {};
};

inline const std::vector<LightCommand>& light_commands() {
    static const std::vector<LightCommand> commands = {
        {"participants", register_participants},
        {"export", register_export},
        {"merge", register_merge},
        {"store", register_store},
        {"analyze", register_analyze, {"--images"}},
        {"stats", register_stats},
        {"simulate", register_simulate},
        {"power", register_power},
    };
    return commands;
}

}  // namespace lucent::app
