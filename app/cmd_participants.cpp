// lucent participants: list the participants of a study database, or withdraw one.
#include <iostream>
#include <memory>
#include <optional>

#include "app/commands.h"
#include "app/study_db_option.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/study_store.h"

namespace lucent::app {
namespace {

int list_participants(const std::string& db_name) {
    const study::ReadableStudyFile source(db_name);  // a server: one snapshot of it
    const std::string& db_path = source.path();
    study::check_database_file(db_path);
    study::Database db(db_path, SQLITE_OPEN_READONLY);
    if (db.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = 'participants'") ==
        0) {
        std::cout << "no participants\n";
        return kExitOk;
    }
    study::Statement s = db.prepare(
        "SELECT p.code, p.number, count(DISTINCT se.id), "
        "(SELECT count(*) FROM responses r JOIN sessions x ON x.id = r.session_id "
        " WHERE x.participant_id = p.id), group_concat(DISTINCT se.status) "
        "FROM participants p LEFT JOIN sessions se ON se.participant_id = p.id "
        "GROUP BY p.id ORDER BY p.code");
    std::cout << "participant  number  sessions  ratings  status\n";
    while (s.step())
        std::cout << s.text(0) << "  " << s.integer(1) << "  " << s.integer(2) << "  "
                  << s.integer(3) << "  " << s.text(4) << "\n";
    return kExitOk;
}

int withdraw(const std::string& db_path, const std::string& code, bool yes) {
    const std::unique_ptr<study::StudyStore> store = study::open_study_store(db_path);
    const std::optional<study::ParticipantCounts> counts =
        store->participant_counts(code);
    if (!counts) {
        std::cerr << "lucent participants withdraw: no participant '" << code << "' in "
                  << db_path << "\n";
        return kExitUsage;
    }
    if (!yes) {
        std::cout << "Delete all data of participant '" << code << "' ("
                  << counts->sessions << " sessions, " << counts->ratings
                  << " ratings) from " << db_path
                  << "? This cannot be undone. Type 'yes' to confirm: " << std::flush;
        std::string answer;
        std::getline(std::cin, answer);
        if (answer != "yes") {
            std::cerr << "lucent participants withdraw: not confirmed; nothing deleted\n";
            return kExitFailure;
        }
    }
    store->withdraw_participant(code);
    std::cout
        << "withdrew participant '" << code
        << "': their sessions and ratings are deleted\n"
        << "Other copies (station files, backups) still hold them until merged: a merge "
           "with this database leaves them out (its withdrawal tombstones)\n";
    return kExitOk;
}

}  // namespace

void register_participants(CLI::App& app, int& exit_code) {
    auto* cmd = app.add_subcommand(
        "participants", "List or withdraw the participants of a study database");
    cmd->require_subcommand(1);
    auto db = std::make_shared<std::string>();
    auto code = std::make_shared<std::string>();
    auto yes = std::make_shared<bool>(false);
    auto* list =
        cmd->add_subcommand("list", "List participants with their sessions and ratings");
    list->add_option("--db", *db, "Study database: FILE.db or postgresql://...")
        ->required()
        ->check(study_db_validator());
    auto* wd = cmd->add_subcommand(
        "withdraw", "Delete a participant and all their data (asks first)");
    wd->add_option("id", *code, "Participant code")->required();
    wd->add_option("--db", *db, "Study database: FILE.db or postgresql://...")
        ->required()
        ->check(study_db_validator());
    wd->add_flag("--yes", *yes, "Do not ask for confirmation (scripts)");
    auto guarded = [&exit_code](auto fn) {
        try {
            exit_code = fn();
        } catch (const study::StoreError& e) {
            std::cerr << "lucent participants: " << e.what() << "\n";
            exit_code = kExitUsage;
        }
    };
    list->callback([=] { guarded([&] { return list_participants(*db); }); });
    wd->callback([=] { guarded([&] { return withdraw(*db, *code, *yes); }); });
}

}  // namespace lucent::app
