// lucent: runs the analysis subcommands (light_commands.h) in this small process and
// execs lucent-full, beside this executable, for everything else (rendering, sessions,
// the explorer, benches, and the top-level --help that lists every subcommand).
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string_view>

#include "app/cli_main.h"
#include "app/light_commands.h"

namespace {

// True when this process can run the command line: a light subcommand without any of
// the options that need lucent-full.
bool is_light(int argc, char** argv) {
    if (argc < 2) return false;
    for (const auto& light : lucent::app::light_commands()) {
        if (light.name != argv[1]) continue;
        for (int i = 2; i < argc; ++i) {
            const std::string_view arg = argv[i];
            for (const std::string_view option : light.full_options)
                if (arg == option ||
                    (arg.size() > option.size() &&
                     arg.substr(0, option.size()) == option && arg[option.size()] == '='))
                    return false;
        }
        return true;
    }
    return false;
}

int exec_full(char** argv) {
    std::error_code error;
    const std::filesystem::path self =
        std::filesystem::read_symlink("/proc/self/exe", error);
    if (error) {
        std::cerr << "lucent: cannot locate this executable (/proc/self/exe: "
                  << error.message() << ")\n";
        return lucent::app::kExitFailure;
    }
    const std::string full = (self.parent_path() / "lucent-full").string();
    argv[0] = const_cast<char*>(full.c_str());
    ::execv(full.c_str(), argv);
    std::cerr << "lucent: cannot start " << full << " (" << std::strerror(errno)
              << "); it is built beside lucent\n";
    return lucent::app::kExitFailure;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace lucent::app;
    if (!is_light(argc, argv)) return exec_full(argv);
    std::vector<Registration> subcommands;
    for (const LightCommand& light : light_commands())
        subcommands.push_back(light.registration);
    return run_cli(argc, argv, subcommands);
}
