#pragma once
// The report's section for paired-comparison and MLDS blocks: per block a heading, the
// fits in words and tables (pooled and per participant), the scale plotted against the
// series' physical parameter (pooled with its intervals and a line per participant, by
// the one plotting code, common/html/svg_plot.h) and the series' pictures in order
// along it. Blocks of the report's document model (analysis/report/document.h), so its
// Markdown and HTML renderers draw them (HTML embeds the pictures).
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "analysis/report/document.h"
#include "analysis/scaling/mlds.h"
#include "analysis/scaling/paired_comparison.h"

namespace lucent::analysis {

struct ScalingSection {
    std::vector<Block> blocks;
    // scaling_<block>.svg per block (the kPlot blocks' SVG, by their file name) and
    // scaling.csv: every scale value, pooled and per participant, full precision.
    ReportFiles files;
};

// `pictures`: stimulus id -> PNG (e.g. DIR/<stimulus>.png of `lucent render`'s output);
// stimuli without one are left out of the row of pictures. Blocks without a series
// value are plotted against their position in the series.
ScalingSection scaling_section(
    const std::vector<PairedBlockFits>& paired, const std::vector<MldsBlockFits>& mlds,
    const std::map<std::string, std::filesystem::path>& pictures = {});

}  // namespace lucent::analysis
