#pragma once
// The analysis entry point: a long table of ratings in (from the CSV reader, the study
// database reader or the simulator), one analysis per (question, factor) pair out.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "data/long_table.h"
#include "stats/one_way_analysis.h"

namespace lucent::analysis {

struct AnalysisRequest {
    double alpha = 0.10;   // the thesis's level; Tukey intervals at 1 - alpha
    std::string question;  // only this question ("" = all)
    std::string factor;    // only this factor ("" = all)
    // Called before each pair is analyzed (progress on long runs); may be empty.
    std::function<void(const std::string& question, const std::string& factor,
                       std::size_t levels)>
        on_pair;
    // The primary design; empty: within when every pair has a within-subject layout.
    std::optional<Design> primary;
};

struct AnalysisResult {
    std::vector<OneWayAnalysis> pairs;
    Design primary = Design::Between;  // the request's, or the one the data allow
};

// Throws InputError when no rating matches the filters.
AnalysisResult analyze_table(const LongTable& table, const AnalysisRequest& request);

}  // namespace lucent::analysis
