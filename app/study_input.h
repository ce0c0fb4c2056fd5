#pragma once
// `lucent analyze` input: a long CSV, or a study database read through study/ (each
// stimulus's parameters as factors; practice, catch and excluded participants dropped).
#include <string>

#include "data/long_table.h"

namespace lucent::app {

// True when `path` starts with the SQLite header.
bool is_sqlite_file(const std::string& path);
// Reads either kind; throws analysis::InputError (one line) on bad input.
analysis::LongTable read_ratings(const std::string& path, const analysis::RatingScale& scale);

}  // namespace lucent::app
