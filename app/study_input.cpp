#include "app/study_input.h"

#include <filesystem>
#include <fstream>
#include <iostream>

#include "analysis/data/observation_csv.h"
#include "study/observations.h"
#include "study/question_scales.h"
#include "study/study_store.h"

namespace lucent::app {
namespace {

std::string first_line(const std::string& path) {
    std::ifstream in(path);
    std::string header;
    std::getline(in, header);
    return header;
}

}  // namespace

bool is_sqlite_file(const std::string& path) {
    char magic[16] = {};
    std::ifstream in(path, std::ios::binary);
    in.read(magic, sizeof magic);
    return in.gcount() == 16 &&
           std::string(magic, 16) == std::string("SQLite format 3\0", 16);
}

bool is_choice_csv(const std::string& path) {
    if (study::is_server_uri(path) || is_sqlite_file(path)) return false;
    const std::string header = first_line(path);
    return header.find("shown_1") != std::string::npos &&
           header.find("choice") != std::string::npos;
}

namespace {

// Ratings, choices and matches: the one table's views.
void read_views(const common::ObservationTable& table, const std::string& path,
                const analysis::RatingScale& scale,
                std::optional<study::Protocol> protocol, AnalysisInput& input) {
    input.ratings = analysis::ratings_of(table, path, scale);
    input.choices = analysis::choices_of(table, path);
    input.matching = analysis::matching_of(table, std::move(protocol));
}

}  // namespace

AnalysisInput read_analysis_input(const std::string& path,
                                  const analysis::RatingScale& scale) {
    AnalysisInput input;
    if (!study::is_server_uri(path) && !is_sqlite_file(path)) {
        if (analysis::is_observation_header(first_line(path))) {
            // An exported study (or a table in its layout): no protocol travels with it.
            read_views(analysis::read_observation_csv(std::filesystem::path(path)), path,
                       scale, std::nullopt, input);
            input.matching.sessions_note = path + ": a table of observations";
        } else if (is_choice_csv(path))
            input.choices = analysis::read_choice_csv(std::filesystem::path(path));
        else
            input.ratings = analysis::read_long_csv(path, scale);
        return input;
    }
    input.from_study = true;
    study::StudyObservations read;
    std::string note;
    try {
        const study::ReadableStudyFile source(path);  // a server: one snapshot of it
        // Each rating on its own question's scale, which the report's plots then use.
        for (const auto& [question, points] : study::check_stored_ratings(source.path()))
            input.question_scales[question] = {false, 1.0, double(points)};
        read = study::read_observations(source.path());
        // The snapshot of a server has a temporary name: the note names what was given.
        note = source.as_given(read.selection.note);
    } catch (const study::StoreError& e) {
        throw analysis::InputError(e.what());
    }
    if (read.protocol) {
        const study::AnalysisPlan& plan = read.protocol->analysis;
        input.plan_model = plan.primary_model;
        if (!plan.primary_design.empty())
            input.plan_design = plan.primary_design == "within"
                                    ? analysis::Design::Within
                                    : analysis::Design::Between;
    }
    for (const std::string& p : read.selection.excluded_participants)
        std::cerr << "lucent analyze: excluded participant " << p << "\n";
    std::cerr << "lucent analyze: note: " << note << "\n";
    input.notes.push_back("Sessions: " + note + ".");
    input.choice_orders = read.choice_orders;
    read_views(read.table, path, scale, std::move(read.protocol), input);
    input.matching.excluded_participants = read.selection.excluded_participants;
    input.matching.sessions_note = note;
    return input;
}

}  // namespace lucent::app
