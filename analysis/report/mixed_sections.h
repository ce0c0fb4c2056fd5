#pragma once
// The report's mixed-model parts: each pair's ordinal (clmm) and linear (lmm) mixed
// model sections, their summary rows, and their CSV tables.
#include <string>
#include <vector>

#include "analysis/report/document.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

// The summary's cells after "configuration" for `model` (clmm or lmm): analysis, test,
// p, statistic, significant at alpha, used. Empty when the pair has no such fit.
std::vector<std::string> mixed_summary_cells(const OneWayAnalysis& pair,
                                             RatingModel model, double alpha);

// The sections of one pair, clmm first.
std::vector<Block> mixed_model_blocks(const OneWayAnalysis& pair);

// mixed_tests.csv and mixed_effects.csv (and ordinal_probabilities.csv), when any pair
// has a mixed model.
void write_mixed_csv_tables(const std::vector<OneWayAnalysis>& analyses,
                            ReportFiles& files);

// The figure's file name for a pair.
std::string ordinal_plot_file_name(const std::string& question,
                                   const std::string& factor);

}  // namespace lucent::analysis
