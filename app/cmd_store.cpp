// lucent store: set up a study store (schema migrations) and send a station's journal.
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "study/postgres/trial_journal.h"
#include "study/sqlite/database.h"
#include "study/study_store.h"

namespace lucent::app {

void register_store(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand(
        "store",
        "Set up a study store, or send the trials a station still holds locally");
    cmd->require_subcommand(1);
    auto db = std::make_shared<std::string>();
    auto journal = std::make_shared<std::string>();
    auto* init = cmd->add_subcommand(
        "init",
        "Create the schema, or apply the migrations this build adds (a newer schema "
        "is refused and left unchanged)");
    init->add_option("--db", *db, "FILE.db or postgresql://USER@HOST[:PORT]/DBNAME")
        ->required();
    auto* sync = cmd->add_subcommand(
        "sync",
        "Send the trials this station's journal holds for a server until it confirms "
        "them (idempotent: a trial the server has is not stored twice)");
    sync->add_option("--db", *db, "postgresql://USER@HOST[:PORT]/DBNAME")->required();
    sync->add_option(
        "--journal", *journal,
        "The journal file (default: the one `lucent run` used for this server)");
    auto guarded = [&exit_code](const char* verb, auto fn) {
        try {
            exit_code = fn();
        } catch (const study::StoreError& e) {
            std::cerr << "lucent store " << verb << ": " << e.what() << "\n";
            exit_code = kExitUsage;
        }
    };
    init->callback([=] {
        guarded("init", [&] {
            const auto [before, after] = study::init_study_store(*db);
            if (before == after)
                std::cout << *db << ": schema " << after << ", up to date\n";
            else
                std::cout << *db << ": schema " << before << " -> " << after << "\n";
            return kExitOk;
        });
    });
    sync->callback([=, &exit_code] {
        guarded("sync", [&] {
            if (!study::is_server_uri(*db))
                throw study::StoreError(
                    "--db " + *db + ": a file store has no journal; sync is for servers");
            study::StoreOptions options;
            options.journal_path =
                journal->empty() ? study::default_journal_path(*db) : *journal;
            // Counted from the journal itself, so an unreachable server still gets a
            // count.
            const int before = study::TrialJournal(options.journal_path, *db).count();
            int left = before, withdrawn = 0;
            // Trials of a session withdrawn on the server leave the journal unsent.
            auto dropped = [&withdrawn] {
                return withdrawn ? "; " + std::to_string(withdrawn) +
                                       " dropped unsent (their participant was withdrawn)"
                                 : std::string();
            };
            try {
                const std::unique_ptr<study::StudyStore> store =
                    study::open_study_store(*db, options);
                try {
                    store->sync();
                } catch (const study::StoreError&) {
                    left = store->pending_trials();
                    withdrawn = store->withdrawn_trials_dropped();
                    throw;
                }
                left = store->pending_trials();
                withdrawn = store->withdrawn_trials_dropped();
            } catch (const study::StoreError& e) {
                std::cerr << "lucent store sync: " << e.what() << "\n";
                std::cout << "sent " << before - left - withdrawn << " of " << before
                          << " trials" << dropped() << "; " << left << " still held in "
                          << options.journal_path << "\n";
                return kExitFailure;
            }
            std::cout << "sent " << before - left - withdrawn << " of " << before
                      << " trials to " << *db << dropped() << "; 0 still held\n";
            return kExitOk;
        });
        (void)exit_code;
    });
}

}  // namespace lucent::app
