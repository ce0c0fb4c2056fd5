#pragma once
// The report's mixed-model parts: each pair's model sections (each model's own, from
// analysis/models/), their summary rows, and their CSV tables.
#include <string>
#include <vector>

#include "analysis/report/document.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

struct RatingModelSpec;

// The summary's cells after "configuration" for `model`: analysis, test, p, statistic,
// significant at alpha, used. Empty when the pair has no such fit.
std::vector<std::string> mixed_summary_cells(const OneWayAnalysis& pair,
                                             const RatingModelSpec& model, double alpha);

// What every model's section says the same way (analysis/models/): "[low, high]" or
// "undefined"; the fit's notes in one paragraph; "12 participants, 8 stimuli, 384
// ratings"; "participant 0.52, stimulus 0.31" or "none".
std::string interval_text(const Statistic& low, const Statistic& high);
std::string fit_notes_text(const RatingModelFit& fit);
std::string fit_counts_text(const RatingModelFit& fit);
std::string random_sds_text(const RatingModelFit& fit);

// The sections of one pair, in registry order (each model's own blocks).
std::vector<Block> mixed_model_blocks(const OneWayAnalysis& pair);

// mixed_tests.csv and mixed_effects.csv (and ordinal_probabilities.csv), when any pair
// has a mixed model.
void write_mixed_csv_tables(const std::vector<OneWayAnalysis>& analyses,
                            ReportFiles& files);

// The figure's file name for a pair.
std::string ordinal_plot_file_name(const std::string& question,
                                   const std::string& factor);

}  // namespace lucent::analysis
