#include "app/cli_main.h"

#include <exception>
#include <iostream>

#include "lucent/version.h"

namespace lucent::app {
namespace {
bool is_subcommand(CLI::App& app, const std::string& name) {
    for (const auto* sub : app.get_subcommands({}))
        if (sub->get_name() == name) return true;
    return false;
}
}  // namespace

int run_cli(int argc, char** argv, const std::vector<Registration>& subcommands) {
    CLI::App app{
        "Lucent: stimuli, participant sessions and analysis for perceptual studies "
        "of translucent-looking objects",
        "lucent"};
    app.set_version_flag("--version", std::string("lucent ") + lucent::version_string() +
                                          " (" + lucent::build_hash() + ")");
    app.require_subcommand(1);
    app.fallthrough(false);

    int exit_code = kExitOk;
    for (const Registration register_subcommand : subcommands)
        register_subcommand(app, exit_code);

    // CLI11 would only say "A subcommand is required"; name the word it did not know.
    if (argc > 1 && argv[1][0] != '-' && !is_subcommand(app, argv[1])) {
        std::string valid;
        for (const auto* sub : app.get_subcommands({}))
            valid += (valid.empty() ? "" : ", ") + sub->get_name();
        std::cerr << "lucent: unknown subcommand '" << argv[1] << "' (valid: " << valid
                  << ")\n";
        return kExitUsage;
    }

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line, then the usual hint; usage errors always exit 2.
        std::cerr << "lucent: " << e.what() << "\n"
                  << "Run 'lucent --help' (or 'lucent SUBCOMMAND --help') for usage.\n";
        return kExitUsage;
    } catch (const std::exception& e) {
        std::cerr << "lucent: " << e.what() << "\n";
        return kExitFailure;
    }
    return exit_code;
}

}  // namespace lucent::app
