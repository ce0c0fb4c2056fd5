// lucent export: a study database as CSV (long, wide, the analysis long table, the
// forced choices, the adjustments and matches, the staircase trials, and every answer
// the analysis reads as one table of observations).
#include <iostream>

#include "app/commands.h"
#include "app/study_db_option.h"
#include "study/export.h"
#include "study/question_scales.h"
#include "study/sqlite/database.h"
#include "study/study_store.h"

namespace lucent::app {

void register_export(CLI::App& app, int& exit_code) {
    auto db = std::make_shared<std::string>();
    auto format = std::make_shared<std::string>("long");
    auto out = std::make_shared<std::string>();
    auto force = std::make_shared<bool>(false);
    auto* cmd = app.add_subcommand(
        "export",
        "Write a study database's ratings, choices, matches or staircases as CSV");
    cmd->add_option("db", *db,
                    "Study database: FILE.db or postgresql://USER@HOST[:PORT]/DBNAME")
        ->required()
        ->check(study_db_validator());
    cmd->add_option(
           "--format", *format,
           "long: one row per rating; wide: one row per participant; analysis: "
           "participant,stimulus,factor,level,question,rating for lucent analyze; "
           "choices: one row per paired-comparison or MLDS choice (the stimuli in "
           "screen order, the choice, RT); choice-analysis: the same as lucent analyze "
           "scales them (no practice, the analysis plan's sessions, participants failing "
           "catch trials left out); adjustments: one row per change of an adjust "
           "trial's knob (value, ms from onset, input); matches: one row per adjust "
           "trial (start, final value, count of adjustments, total ms); staircase: one "
           "row per answered staircase trial (intensity, expected, choice, correct, RT); "
           "observations: every answer lucent analyze reads, of every kind, one row "
           "each with a column per factor")
        ->check(CLI::IsMember({"long", "wide", "analysis", "choices", "choice-analysis",
                               "adjustments", "matches", "staircase", "observations"}));
    cmd->add_option("--out", *out,
                    "CSV file to write (never a database; written to a temporary file in "
                    "its folder, then renamed)")
        ->required();
    cmd->add_flag("--force", *force, "Replace an existing --out file (never a database)");
    cmd->callback([=, &exit_code] {
        try {
            const study::ReadableStudyFile source(*db);  // a server: one snapshot of it
            const study::ExportFileResult r =
                study::export_file(source.path(), *format, *out, *force);
            for (const std::string& p : r.excluded_participants)
                std::cerr << "lucent export: excluded " << p << "\n";
            for (const std::string& note : r.notes)  // on stderr: the CSV stays plain
                std::cerr << "lucent export: note: " << source.as_given(note) << "\n";
            std::cout << "wrote " << r.rows << " rows to " << *out << "\n";
            exit_code = kExitOk;
        } catch (const study::StoreError& e) {
            std::cerr << "lucent export: " << e.what() << "\n";
            exit_code = kExitUsage;
        }
    });
}

}  // namespace lucent::app
