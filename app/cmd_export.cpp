// lucent export: a study database as CSV (long, wide, or the analysis long table).
#include <filesystem>
#include <fstream>
#include <iostream>

#include "commands.h"
#include "export.h"
#include "question_scales.h"
#include "sqlite.h"

namespace lucent::app {
namespace {

int export_command(const std::string& db, const std::string& format, const std::string& out_path) {
    const std::string tmp = out_path + ".partial";
    int rows = 0;
    try {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) {
            std::cerr << "lucent export: " << out_path << ": cannot write\n";
            return kExitFailure;
        }
        if (format == "analysis") {
            study::check_stored_ratings(db);  // no impossible rating enters an analysis
            const study::LongTable table = study::analysis_long_table(db);
            study::write_long_table_csv(table, out);
            rows = static_cast<int>(table.rows.size());
            for (const std::string& p : table.excluded_participants)
                std::cerr << "lucent export: excluded " << p << "\n";
        } else {
            std::vector<std::string> notes;  // on stderr: the CSV stays plain for readers
            rows = study::export_csv(db, format == "long" ? study::ExportFormat::Long
                                                          : study::ExportFormat::Wide,
                                     out, &notes);
            for (const std::string& note : notes)
                std::cerr << "lucent export: note: " << note << "\n";
        }
        out.close();
        if (!out) throw study::StoreError(out_path + ": write failed");
    } catch (const study::StoreError& e) {
        std::filesystem::remove(tmp);
        std::cerr << "lucent export: " << e.what() << "\n";
        return kExitUsage;
    }
    std::filesystem::rename(tmp, out_path);  // never a half-written CSV under the real name
    std::cout << "wrote " << rows << " rows to " << out_path << "\n";
    return kExitOk;
}

}  // namespace

void register_export(CLI::App& app, int& exit_code) {
    auto db = std::make_shared<std::string>();
    auto format = std::make_shared<std::string>("long");
    auto out = std::make_shared<std::string>();
    auto* cmd = app.add_subcommand("export", "Write a study database's ratings as CSV");
    cmd->add_option("db", *db, "Study database")->required()->check(CLI::ExistingFile);
    cmd->add_option("--format", *format,
                    "long: one row per rating; wide: one row per participant; analysis: "
                    "participant,stimulus,factor,level,question,rating for lucent analyze")
        ->check(CLI::IsMember({"long", "wide", "analysis"}));
    cmd->add_option("--out", *out, "CSV file to write")->required();
    cmd->callback([=, &exit_code] { exit_code = export_command(*db, *format, *out); });
}

}  // namespace lucent::app
