#pragma once
// `lucent analyze` input: a long CSV, or a study database read through study/ (each
// stimulus's parameters as factors; practice, catch and excluded participants dropped).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/choice_table.h"
#include "analysis/data/long_table.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::app {

// True when `path` starts with the SQLite header.
bool is_sqlite_file(const std::string& path);
// Reads either kind; throws analysis::InputError (one line) on bad input. For a study
// database, `plan_design` receives the stored protocol's primary design, and `notes` the
// line saying how many sessions were analysed and left out, by reason (also on stderr),
// and `question_scales` each rated question's scale (1..points) from its protocol.
analysis::LongTable read_ratings(
    const std::string& path, const analysis::RatingScale& scale,
    std::optional<analysis::Design>* plan_design = nullptr,
    std::vector<std::string>* notes = nullptr,
    std::map<std::string, analysis::RatingScale>* question_scales = nullptr,
    std::string* plan_model = nullptr);

// The forced choices (paired comparisons, MLDS) of a study database, as the analysis
// reads them (practice left out, the plan's sessions, failed catch trials' participants
// excluded), or of a `lucent export --format choices` CSV. Empty rows when the input
// holds none (a database of ratings only, or a ratings CSV). `orders`: each choice
// block's series as the stored protocol lists it (databases only).
analysis::ChoiceTable read_choices(
    const std::string& path, std::map<std::string, std::vector<std::string>>* orders);
// True when `path` is a CSV whose header names the choices' columns (shown_1, choice).
bool is_choice_csv(const std::string& path);

}  // namespace lucent::app
