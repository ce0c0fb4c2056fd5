#pragma once
// A small SVG chart: mean rating per level with 95% CI error bars (a few lines of text,
// no plotting library).
#include <string>
#include <vector>

#include "stats/descriptives.h"

namespace lucent::analysis {

std::string mean_ci_plot_svg(const std::string& title, const std::string& y_label,
                             const std::vector<Descriptives>& levels);

}  // namespace lucent::analysis
