#include "app/study_input.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "study/export.h"
#include "study/question_scales.h"
#include "study/sqlite/database.h"
#include "study/study_store.h"

namespace lucent::app {

bool is_sqlite_file(const std::string& path) {
    char magic[16] = {};
    std::ifstream in(path, std::ios::binary);
    in.read(magic, sizeof magic);
    return in.gcount() == 16 &&
           std::string(magic, 16) == std::string("SQLite format 3\0", 16);
}

analysis::LongTable read_ratings(
    const std::string& path, const analysis::RatingScale& scale,
    std::optional<analysis::Design>* plan_design, std::vector<std::string>* notes,
    std::map<std::string, analysis::RatingScale>* question_scales,
    std::string* plan_model) {
    const bool server = study::is_server_uri(path);
    if (!server && !is_sqlite_file(path)) return analysis::read_long_csv(path, scale);
    study::LongTable rows;
    std::string note;
    try {
        const study::ReadableStudyFile source(path);  // a server: one snapshot of it
        // Each rating on its own question's scale, which the report's plots then use.
        for (const auto& [question, points] : study::check_stored_ratings(source.path()))
            if (question_scales)
                (*question_scales)[question] = {false, 1.0, double(points)};
        rows = study::analysis_long_table(source.path());
        note = source.as_given(rows.sessions_note);
    } catch (const study::StoreError& e) {
        throw analysis::InputError(e.what());
    }
    if (plan_model) *plan_model = rows.primary_model;
    if (plan_design && !rows.primary_design.empty())
        *plan_design = rows.primary_design == "within" ? analysis::Design::Within
                                                       : analysis::Design::Between;
    for (const std::string& p : rows.excluded_participants)
        std::cerr << "lucent analyze: excluded participant " << p << "\n";
    // The snapshot of a server has a temporary name: the note names what was given.
    std::cerr << "lucent analyze: note: " << note << "\n";
    if (notes) notes->push_back("Sessions: " + note + ".");
    analysis::LongTable table;
    for (size_t i = 0; i < rows.rows.size(); ++i) {
        const study::LongRow& r = rows.rows[i];
        table.rows.push_back({r.participant, r.stimulus, r.factor, r.level, r.question,
                              static_cast<double>(r.rating), i + 1});
    }
    analysis::check_scale(table, scale, path);
    return table;
}

bool is_choice_csv(const std::string& path) {
    if (study::is_server_uri(path) || is_sqlite_file(path)) return false;
    std::ifstream in(path);
    std::string header;
    std::getline(in, header);
    return header.find("shown_1") != std::string::npos &&
           header.find("choice") != std::string::npos;
}

analysis::ChoiceTable read_choices(
    const std::string& path, std::map<std::string, std::vector<std::string>>* orders) {
    const bool server = study::is_server_uri(path);
    if (!server && !is_sqlite_file(path)) {
        if (!is_choice_csv(path)) return {};
        return analysis::read_choice_csv(std::filesystem::path(path));
    }
    try {
        const study::ReadableStudyFile source(path);
        std::stringstream csv;
        const study::ChoiceExport choices =
            study::export_choices(source.path(), csv, {.analysis = true});
        if (orders)
            for (const auto& [block, stimuli] : study::choice_block_orders(source.path()))
                (*orders)[block] = stimuli;
        for (const std::string& p : choices.excluded_participants)
            std::cerr << "lucent analyze: excluded participant " << p
                      << " from the scales\n";
        return analysis::read_choice_csv(csv, path);
    } catch (const study::StoreError& e) {
        throw analysis::InputError(e.what());
    }
}

}  // namespace lucent::app
