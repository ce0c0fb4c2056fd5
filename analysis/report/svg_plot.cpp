#include "analysis/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/html/html_page.h"
#include "common/html/svg_plot.h"

namespace lucent::analysis {
namespace {

using common::markup_escape;
using common::padded_range;
using common::svg_header;
using common::svg_number;

// The defined means and CI ends of `levels`, widened into [lo, hi].
void widen_range(const std::vector<Descriptives>& levels, double& lo, double& hi) {
    for (const Descriptives& d : levels)
        for (const Statistic& v : {d.mean, d.ci_low, d.ci_high})
            if (v && std::isfinite(*v)) {
                lo = std::min(lo, *v);
                hi = std::max(hi, *v);
            }
}

// One panel's axes, ticks, level labels and mean/CI marks, at (x0, y0), size w x h.
void draw_panel(std::ostringstream& svg, double x0, double y0, double w, double h,
                double lo, double hi, const std::string& title,
                const std::string& y_label, const std::vector<Descriptives>& levels,
                const std::string& x_label) {
    constexpr double kLeft = 60, kRight = 20, kTop = 40, kBottom = 60;
    const double left = x0 + kLeft, top = y0 + kTop;
    const double plot_w = w - kLeft - kRight, plot_h = h - kTop - kBottom;
    auto y_of = [&](double v) { return top + plot_h * (hi - v) / (hi - lo); };
    const std::size_t n = std::max<std::size_t>(levels.size(), 1);
    auto x_of = [&](std::size_t i) { return left + plot_w * (i + 0.5) / n; };
    svg << "<text x=\"" << svg_number(x0 + w / 2) << "\" y=\"" << svg_number(y0 + 20)
        << "\" text-anchor=\"middle\" font-size=\"14\">" << markup_escape(title)
        << "</text>\n"
        << "<line x1=\"" << left << "\" y1=\"" << top << "\" x2=\"" << left << "\" y2=\""
        << top + plot_h << "\" stroke=\"black\"/>\n"
        << "<line x1=\"" << left << "\" y1=\"" << top + plot_h << "\" x2=\""
        << left + plot_w << "\" y2=\"" << top + plot_h << "\" stroke=\"black\"/>\n";
    for (int t = 0; t <= 4; ++t) {
        const double v = lo + (hi - lo) * t / 4.0;
        svg << "<line x1=\"" << left - 4 << "\" y1=\"" << svg_number(y_of(v))
            << "\" x2=\"" << left << "\" y2=\"" << svg_number(y_of(v))
            << "\" stroke=\"black\"/>"
            << "<text x=\"" << left - 6 << "\" y=\"" << svg_number(y_of(v) + 4)
            << "\" text-anchor=\"end\">" << svg_number(v) << "</text>\n";
    }
    svg << "<text x=\"" << svg_number(x0 + 14) << "\" y=\""
        << svg_number(top + plot_h / 2)
        << "\" text-anchor=\"middle\" transform=\"rotate(-90 " << svg_number(x0 + 14)
        << ' ' << svg_number(top + plot_h / 2) << ")\">" << markup_escape(y_label)
        << "</text>\n";
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const Descriptives& d = levels[i];
        const double x = x_of(i);
        svg << "<text x=\"" << svg_number(x) << "\" y=\"" << svg_number(top + plot_h + 18)
            << "\" text-anchor=\"middle\">" << markup_escape(d.level) << "</text>\n";
        if (d.ci_low && d.ci_high) {
            svg << "<line x1=\"" << svg_number(x) << "\" y1=\""
                << svg_number(y_of(*d.ci_low)) << "\" x2=\"" << svg_number(x)
                << "\" y2=\"" << svg_number(y_of(*d.ci_high)) << "\" stroke=\"#444\"/>";
            for (double end : {*d.ci_low, *d.ci_high})
                svg << "<line x1=\"" << svg_number(x - 6) << "\" y1=\""
                    << svg_number(y_of(end)) << "\" x2=\"" << svg_number(x + 6)
                    << "\" y2=\"" << svg_number(y_of(end)) << "\" stroke=\"#444\"/>";
            svg << "\n";
        }
        if (d.mean)
            svg << "<circle cx=\"" << svg_number(x) << "\" cy=\""
                << svg_number(y_of(*d.mean)) << "\" r=\"4\" fill=\"#1f77b4\"/>\n";
    }
    svg << "<text x=\"" << svg_number(left + plot_w / 2) << "\" y=\""
        << svg_number(y0 + h - 12) << "\" text-anchor=\"middle\">"
        << markup_escape(x_label) << " (mean with 95% CI)</text>\n";
}

}  // namespace

std::string mean_ci_plot_svg(const std::string& title, const std::string& y_label,
                             const std::vector<Descriptives>& levels,
                             const std::string& x_label) {
    constexpr double kWidth = 480, kHeight = 320;
    double lo = INFINITY, hi = -INFINITY;
    widen_range(levels, lo, hi);
    padded_range(lo, hi);
    std::ostringstream svg;
    svg << svg_header(kWidth, kHeight);
    draw_panel(svg, 0, 0, kWidth, kHeight, lo, hi, title, y_label, levels, x_label);
    svg << "</svg>\n";
    return svg.str();
}

std::string factor_figure_svg(const std::string& factor,
                              const std::vector<QuestionPanel>& panels) {
    constexpr double kPanelWidth = 320, kHeight = 320;
    double lo = INFINITY, hi = -INFINITY;  // shared, so panels compare at a glance
    for (const QuestionPanel& p : panels) widen_range(p.levels, lo, hi);
    padded_range(lo, hi);
    const double width = kPanelWidth * std::max<std::size_t>(panels.size(), 1);
    std::ostringstream svg;
    svg << svg_header(width, kHeight + 24);
    svg << "<text x=\"" << svg_number(width / 2) << "\" y=\"16\" text-anchor=\"middle\" "
        << "font-size=\"15\" font-weight=\"bold\">" << markup_escape(factor)
        << "</text>\n";
    for (std::size_t i = 0; i < panels.size(); ++i)
        draw_panel(svg, kPanelWidth * i, 24, kPanelWidth, kHeight, lo, hi,
                   panels[i].question, "mean rating", panels[i].levels, factor);
    svg << "</svg>\n";
    return svg.str();
}

}  // namespace lucent::analysis
