#pragma once
// The table of observations (common/observation_table.h) read back from the CSV that
// `lucent export --format observations` writes, so that `lucent analyze` reads an
// exported study, or an analyst's own table in that layout, through the same views as
// a study database: ratings, forced choices and matches.
#include <filesystem>
#include <istream>
#include <string>

#include "common/observation_table.h"

namespace lucent::analysis {

// True when a CSV header names the observations' columns (kind and response).
bool is_observation_header(const std::string& header_line);

// Columns in any order: participant, kind and response are required; session, trial,
// block, question, practice, catch, expected, shown (stimulus ids separated by
// spaces), rt_ms and procedure are optional; start_value, adjustments, intensity and
// value_1..value_4 are measures; every other column is a factor ("factor:NAME" is the
// factor NAME), an empty cell no level. Throws InputError naming source:line, the column
// and the field.
common::ObservationTable read_observation_csv(std::istream& in,
                                              const std::string& source);
common::ObservationTable read_observation_csv(const std::filesystem::path& path);

}  // namespace lucent::analysis
