#pragma once
// The report's sections for adjust and staircase blocks (issue 31): "Matching" (a table
// of the matches per condition against the target's value, with the bias and the
// constancy index, per-participant means, and a plot of match against target with the
// identity line per block) and "Thresholds" (the JND per participant and standard with
// its bootstrap interval, each procedure's own estimate, a plot of every staircase's
// track with its reversals and answers, and the fitted psychometric functions over the
// binned proportions correct). Blocks of the report's document model (analysis/report/
// document.h), drawn by the one plotting code (common/html/svg_plot.h); each section is
// left out when the study has no such trials.
#include <vector>

#include "analysis/matching/matching.h"
#include "analysis/matching/thresholds.h"
#include "analysis/report/document.h"

namespace lucent::analysis {

struct MatchingSection {
    std::vector<Block> blocks;
    // matching_<block>.svg, staircase and psychometric plots (the kPlot blocks' SVG, by
    // their file names), matching.csv and thresholds.csv (full precision).
    ReportFiles files;
};

MatchingSection matching_section(const std::vector<ConditionMatch>& matches,
                                 const ThresholdAnalysis& thresholds);

}  // namespace lucent::analysis
