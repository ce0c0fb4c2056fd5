// lucent merge: combine study databases from several lab machines.
#include <iostream>

#include "commands.h"
#include "export.h"
#include "sqlite.h"

namespace lucent::app {

void register_merge(CLI::App& app, int& exit_code) {
    auto inputs = std::make_shared<std::vector<std::string>>();
    auto out = std::make_shared<std::string>();
    auto* cmd = app.add_subcommand(
        "merge",
        "Combine study databases (sessions de-duplicated by UUID, a participant is a code on "
        "one machine; one protocol only)");
    cmd->add_option("inputs", *inputs, "Databases to merge")->required()->check(CLI::ExistingFile);
    cmd->add_option("--out", *out, "New database to write (must not exist)")->required();
    cmd->callback([=, &exit_code] {
        try {
            const study::MergeReport r = study::merge_databases(*inputs, *out);
            for (const std::string& note : r.notes) std::cout << "lucent merge: " << note << "\n";
            std::cout << "merged " << inputs->size() << " databases into " << *out << ": "
                      << r.sessions_added << " sessions, " << r.sessions_already_present
                      << " duplicates skipped\n";
            exit_code = kExitOk;
        } catch (const study::StoreError& e) {
            std::cerr << "lucent merge: " << e.what() << "\n";
            exit_code = kExitUsage;
        }
    });
}

}  // namespace lucent::app
