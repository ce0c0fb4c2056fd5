#pragma once
// A small SVG chart: mean rating per level with 95% CI error bars (a few lines of text,
// no plotting library).
#include <string>
#include <vector>

#include "analysis/stats/descriptives.h"

namespace lucent::analysis {

// Levels in the order given (the report passes them in parameter order); `x_label` names
// the factor (e.g. "thickness_exponent") under the level values.
std::string mean_ci_plot_svg(const std::string& title, const std::string& y_label,
                             const std::vector<Descriptives>& levels,
                             const std::string& x_label = "level");

// One figure per factor with one panel per question side by side, on a shared y axis
// (the rating scale's range when given, else the data's), like the thesis's Fig. 4.5.
struct QuestionPanel {
    std::string question;
    std::vector<Descriptives> levels;
};
std::string factor_figure_svg(const std::string& factor,
                              const std::vector<QuestionPanel>& panels);

}  // namespace lucent::analysis
