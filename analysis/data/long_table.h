#pragma once
// The long table the one-way tests and mixed models start from: one row per (rating,
// factor). The CSV reader fills it from `participant,stimulus,factor,level,question,
// rating`; a study's observations (common/observation_table.h) give the same rows.
#include <cstddef>
#include <filesystem>
#include <istream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/data/label.h"
#include "common/observation_table.h"

namespace lucent::analysis {

// Bad input data: the message names the file and line (or row) and the field.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct RatingRow {
    Label participant, stimulus, factor, level, question;
    std::optional<double> rating;  // relative to LongTable::origin; empty: missing rating
    std::size_t source_line = 0;   // CSV line (or database row) for error messages
};

struct LongTable {
    double origin = 0.0;  // ratings are stored as (value - origin), subtracted exactly
    std::vector<RatingRow> rows;
};

// Accepted rating values: a closed interval (Likert scales) or any finite number.
struct RatingScale {
    bool any = false;
    double min = 1.0, max = 7.0;
};

// "MIN..MAX" (e.g. "1..7", "0..100") or "any"; throws InputError otherwise.
RatingScale parse_scale(std::string_view text);
std::string describe_scale(const RatingScale& scale);

// Throws InputError naming `source:line` of the first rating outside the scale.
void check_scale(const LongTable& table, const RatingScale& scale,
                 const std::string& source);

// Reads the long CSV (header required, columns in any order, RFC 4180 quotes, CRLF or LF;
// an empty rating is a missing value). Ratings are checked against the scale.
LongTable read_long_csv(std::istream& in, const std::string& source,
                        const RatingScale& scale);
LongTable read_long_csv(const std::filesystem::path& path, const RatingScale& scale);

// The ratings of a study's observations, one row per (rating, factor) as
// common::factor_ratings gives them; `source` names the study in errors. Ratings are
// checked against the scale.
LongTable ratings_of(const common::ObservationTable& observations,
                     const std::string& source, const RatingScale& scale);

// Writes the same format (used by the simulator); ratings are printed exactly.
void write_long_csv(std::ostream& out, const LongTable& table);

}  // namespace lucent::analysis
