#include "analysis/report/rating_figures.h"

#include <cmath>

#include "common/html/svg_plot.h"

namespace lucent::analysis {
namespace {

double value_of(const Statistic& s) { return s ? *s : NAN; }

common::PlotPanel panel_of(const std::string& title, const std::string& y_label,
                           const std::vector<Descriptives>& levels,
                           const std::string& x_label) {
    common::PlotPanel panel;
    panel.title = title;
    panel.y_label = y_label;
    panel.x_label = x_label + " (mean with 95% CI)";
    panel.join = false;
    for (const Descriptives& d : levels) {
        panel.categories.push_back(d.level);
        panel.y.push_back(value_of(d.mean));
        panel.y_low.push_back(value_of(d.ci_low));
        panel.y_high.push_back(value_of(d.ci_high));
    }
    return panel;
}

// The rating scale's axis, or (scale "any") one over every panel's means and intervals.
common::Axis rating_axis(const std::vector<common::PlotPanel>& panels,
                         const RatingScale& scale) {
    if (!scale.any) {
        const bool integers =
            scale.min == std::floor(scale.min) && scale.max == std::floor(scale.max);
        return common::fixed_axis(scale.min, scale.max, 8, integers);
    }
    std::vector<double> values;
    for (const auto& p : panels)
        for (const auto* v : {&p.y, &p.y_low, &p.y_high})
            values.insert(values.end(), v->begin(), v->end());
    return common::choose_axis(values, {common::AxisScale::linear, 6, false});
}

}  // namespace

std::string mean_ci_plot_svg(const std::string& title, const std::string& y_label,
                             const std::vector<Descriptives>& levels,
                             const std::string& x_label, const RatingScale& scale) {
    std::vector<common::PlotPanel> panels{panel_of(title, y_label, levels, x_label)};
    panels[0].fixed_y = rating_axis(panels, scale);
    return common::figure_svg("", panels, {480, 320, 1});
}

std::string factor_figure_svg(const std::string& factor,
                              const std::vector<QuestionPanel>& questions,
                              const RatingScale& scale) {
    std::vector<common::PlotPanel> panels;
    for (const QuestionPanel& q : questions)
        panels.push_back(panel_of(q.question, "mean rating", q.levels, factor));
    const common::Axis shared = rating_axis(panels, scale);  // panels compare at a glance
    for (auto& p : panels) p.fixed_y = shared;
    return common::figure_svg(factor, panels, {320, 320, 3});
}

}  // namespace lucent::analysis
