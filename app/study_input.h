#pragma once
// `lucent analyze` input, read once: a study database (a server's through one snapshot)
// as its observations (study/observations.h), out of which come the ratings, the forced
// choices and the matches; or the same table as CSV (`lucent export --format
// observations`: the same views, without the stored protocol); or a long CSV of
// ratings; or a choices CSV.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/choice_table.h"
#include "analysis/data/long_table.h"
#include "analysis/data/matching_table.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::app {

struct AnalysisInput {
    analysis::LongTable ratings;
    analysis::ChoiceTable choices;
    // Each forced-choice block's series as the stored protocol lists it (databases).
    std::map<std::string, std::vector<std::string>> choice_orders;
    analysis::MatchingTable matching;  // databases only
    bool from_study = false;           // a study database (or server), not a CSV
    // The stored protocol's [analysis] plan: its primary design and model.
    std::optional<analysis::Design> plan_design;
    std::string plan_model;
    // The line saying how many sessions were analysed and left out, by reason.
    std::vector<std::string> notes;
    // Each rated question's scale (1..points) from the stored protocol.
    std::map<std::string, analysis::RatingScale> question_scales;
};

// True when `path` starts with the SQLite header.
bool is_sqlite_file(const std::string& path);
// True when `path` is a CSV whose header names the choices' columns (shown_1, choice).
bool is_choice_csv(const std::string& path);

// Reads either kind; throws analysis::InputError (one line) on bad input. Ratings are
// checked against `scale`. The excluded participants and the sessions note also go to
// stderr.
AnalysisInput read_analysis_input(const std::string& path,
                                  const analysis::RatingScale& scale);

}  // namespace lucent::app
