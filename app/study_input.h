#pragma once
// `lucent analyze` input: a long CSV, or a study database read through study/ (each
// stimulus's parameters as factors; practice, catch and excluded participants dropped).
#include <map>
#include <optional>
#include <string>
#include <vector>

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

}  // namespace lucent::app
