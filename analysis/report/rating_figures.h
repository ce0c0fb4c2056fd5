#pragma once
// The analysis report's figures: mean rating per level with its 95% CI, drawn by the
// one plotting code (common/html/svg_plot.h). The y axis is the rating scale (1..7,
// ticks at integers), so a figure never runs past the scale; an interval that reaches
// beyond it stops at the axis with a triangle. With the scale "any", the axis is the
// data's.
#include <string>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/stats/descriptives.h"

namespace lucent::analysis {

// Levels in the order given (the report passes them in parameter order); `x_label` names
// the factor (e.g. "thickness_exponent") under the level values.
std::string mean_ci_plot_svg(const std::string& title, const std::string& y_label,
                             const std::vector<Descriptives>& levels,
                             const std::string& x_label = "level",
                             const RatingScale& scale = {});

// One figure per factor with one panel per question (up to three a row, wrapping), on a
// shared y axis, like the thesis's Fig. 4.5.
struct QuestionPanel {
    std::string question;
    std::vector<Descriptives> levels;
};
std::string factor_figure_svg(const std::string& factor,
                              const std::vector<QuestionPanel>& panels,
                              const RatingScale& scale = {});

}  // namespace lucent::analysis
