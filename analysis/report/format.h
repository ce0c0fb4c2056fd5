#pragma once
// Number formatting for tables: no NaN or Inf ever reaches a report. Undefined values
// print as "undefined", infinities as "inf", and p-values below 1e-300 (underflow) as
// "< 1e-300".
#include <string>

#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

inline constexpr double kSmallestReportedP = 1e-300;

// Full precision (17 significant digits, round-trips exactly): CSV and the stats CLI.
std::string format_full(const Statistic& value);
std::string format_p_full(const Statistic& p);
// Readable precision (4 significant digits): Markdown and HTML.
std::string format_short(const Statistic& value);
std::string format_p_short(const Statistic& p);

}  // namespace lucent::analysis
