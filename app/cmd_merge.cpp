// lucent merge: combine study databases from several lab machines.
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/study_db_option.h"
#include "study/export.h"
#include "study/postgres/merge_into_server.h"
#include "study/sqlite/database.h"
#include "study/study_store.h"

namespace lucent::app {
namespace {

// ", 1 session extended by a later copy, 2 sessions of withdrawn participants not
// merged" (each part only when it happened).
std::string reconciled(const study::MergeReport& r) {
    auto sessions = [](int n) {
        return std::to_string(n) + (n == 1 ? " session" : " sessions");
    };
    std::string out;
    if (r.sessions_extended > 0)
        out += ", " + sessions(r.sessions_extended) +
               " extended by a later copy (the copy with every answer kept)";
    if (r.sessions_withdrawn > 0)
        out += ", " + sessions(r.sessions_withdrawn) +
               " of withdrawn participants not merged";
    return out;
}

}  // namespace

void register_merge(CLI::App& app, int& exit_code) {
    auto inputs = std::make_shared<std::vector<std::string>>();
    auto out = std::make_shared<std::string>();
    auto* cmd = app.add_subcommand(
        "merge",
        "Combine study databases (copies of a session reconciled by UUID, withdrawn "
        "participants left out, a participant is a code on one machine; one protocol "
        "only)");
    cmd->add_option("inputs", *inputs,
                    "Databases to merge: FILE.db or postgresql://... URIs")
        ->required()
        ->check(study_db_validator());
    cmd->add_option(
           "--out", *out,
           "New database to write (must not exist), or a postgresql:// server to add "
           "the sessions it lacks to")
        ->required();
    cmd->callback([=, &exit_code] {
        try {
            // Servers are read through one snapshot each, so merge sees only files.
            std::vector<std::unique_ptr<study::ReadableStudyFile>> sources;
            std::vector<std::string> files;
            for (const std::string& in : *inputs) {
                sources.push_back(std::make_unique<study::ReadableStudyFile>(in));
                files.push_back(sources.back()->path());
            }
            if (study::is_server_uri(*out)) {
                const study::MergeReport r =
                    study::merge_into_server(files, *out, *inputs);
                for (const std::string& note : r.notes)
                    std::cout << "lucent merge: " << note << "\n";
                std::cout << "merged " << inputs->size() << " databases into " << *out
                          << ": " << r.sessions_added << " sessions added, "
                          << r.sessions_already_present << " already there"
                          << reconciled(r) << "\n";
                exit_code = kExitOk;
                return;
            }
            const study::MergeReport r = study::merge_databases(files, *out, *inputs);
            for (const std::string& note : r.notes)
                std::cout << "lucent merge: " << note << "\n";
            std::cout << "merged " << inputs->size() << " databases into " << *out << ": "
                      << r.sessions_added << " sessions, " << r.sessions_already_present
                      << " duplicates skipped" << reconciled(r) << "\n";
            exit_code = kExitOk;
        } catch (const study::StoreError& e) {
            std::cerr << "lucent merge: " << e.what() << "\n";
            exit_code = kExitUsage;
        }
    });
}

}  // namespace lucent::app
