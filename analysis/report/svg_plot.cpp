#include "analysis/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace lucent::analysis {
namespace {

std::string escape_xml(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string num(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f", x);
    return buffer;
}

// The defined means and CI ends of `levels`, widened into [lo, hi].
void widen_range(const std::vector<Descriptives>& levels, double& lo, double& hi) {
    for (const Descriptives& d : levels)
        for (const Statistic& v : {d.mean, d.ci_low, d.ci_high})
            if (v && std::isfinite(*v)) {
                lo = std::min(lo, *v);
                hi = std::max(hi, *v);
            }
}

// A range that can be drawn: a default when nothing is defined, never zero-height,
// padded by 5%.
void padded_range(double& lo, double& hi) {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12 * std::max(1.0, std::fabs(hi))) lo -= 0.5, hi += 0.5;
    const double pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
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
    svg << "<text x=\"" << num(x0 + w / 2) << "\" y=\"" << num(y0 + 20)
        << "\" text-anchor=\"middle\" font-size=\"14\">" << escape_xml(title)
        << "</text>\n"
        << "<line x1=\"" << left << "\" y1=\"" << top << "\" x2=\"" << left << "\" y2=\""
        << top + plot_h << "\" stroke=\"black\"/>\n"
        << "<line x1=\"" << left << "\" y1=\"" << top + plot_h << "\" x2=\""
        << left + plot_w << "\" y2=\"" << top + plot_h << "\" stroke=\"black\"/>\n";
    for (int t = 0; t <= 4; ++t) {
        const double v = lo + (hi - lo) * t / 4.0;
        svg << "<line x1=\"" << left - 4 << "\" y1=\"" << num(y_of(v)) << "\" x2=\""
            << left << "\" y2=\"" << num(y_of(v)) << "\" stroke=\"black\"/>"
            << "<text x=\"" << left - 6 << "\" y=\"" << num(y_of(v) + 4)
            << "\" text-anchor=\"end\">" << num(v) << "</text>\n";
    }
    svg << "<text x=\"" << num(x0 + 14) << "\" y=\"" << num(top + plot_h / 2)
        << "\" text-anchor=\"middle\" transform=\"rotate(-90 " << num(x0 + 14) << ' '
        << num(top + plot_h / 2) << ")\">" << escape_xml(y_label) << "</text>\n";
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const Descriptives& d = levels[i];
        const double x = x_of(i);
        svg << "<text x=\"" << num(x) << "\" y=\"" << num(top + plot_h + 18)
            << "\" text-anchor=\"middle\">" << escape_xml(d.level) << "</text>\n";
        if (d.ci_low && d.ci_high) {
            svg << "<line x1=\"" << num(x) << "\" y1=\"" << num(y_of(*d.ci_low))
                << "\" x2=\"" << num(x) << "\" y2=\"" << num(y_of(*d.ci_high))
                << "\" stroke=\"#444\"/>";
            for (double end : {*d.ci_low, *d.ci_high})
                svg << "<line x1=\"" << num(x - 6) << "\" y1=\"" << num(y_of(end))
                    << "\" x2=\"" << num(x + 6) << "\" y2=\"" << num(y_of(end))
                    << "\" stroke=\"#444\"/>";
            svg << "\n";
        }
        if (d.mean)
            svg << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y_of(*d.mean))
                << "\" r=\"4\" fill=\"#1f77b4\"/>\n";
    }
    svg << "<text x=\"" << num(left + plot_w / 2) << "\" y=\"" << num(y0 + h - 12)
        << "\" text-anchor=\"middle\">" << escape_xml(x_label)
        << " (mean with 95% CI)</text>\n";
}

std::string svg_header(double width, double height) {
    std::ostringstream svg;
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
        << height << "\" viewBox=\"0 0 " << width << ' ' << height
        << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    return svg.str();
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
    svg << "<text x=\"" << num(width / 2) << "\" y=\"16\" text-anchor=\"middle\" "
        << "font-size=\"15\" font-weight=\"bold\">" << escape_xml(factor) << "</text>\n";
    for (std::size_t i = 0; i < panels.size(); ++i)
        draw_panel(svg, kPanelWidth * i, 24, kPanelWidth, kHeight, lo, hi,
                   panels[i].question, "mean rating", panels[i].levels, factor);
    svg << "</svg>\n";
    return svg.str();
}

}  // namespace lucent::analysis

namespace lucent::analysis {

std::string markup_escape(const std::string& text) { return escape_xml(text); }

std::string histogram_svg(const std::string& title, const std::vector<double>& shares,
                          const std::string& x_label) {
    constexpr double kWidth = 200, kHeight = 120, kLeft = 34, kRight = 8, kTop = 20,
                     kBottom = 30;
    const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
    double top_share = 0.0;
    for (double s : shares)
        if (std::isfinite(s)) top_share = std::max(top_share, s);
    if (!(top_share > 0.0)) top_share = 1.0;
    std::ostringstream svg;
    svg << svg_header(kWidth, kHeight);
    svg << "<text x=\"" << num(kWidth / 2) << "\" y=\"14\" text-anchor=\"middle\" "
        << "font-size=\"11\">" << escape_xml(title) << "</text>\n";
    const double bar_w = plot_w / double(std::max<std::size_t>(shares.size(), 1));
    for (std::size_t i = 0; i < shares.size(); ++i) {
        const double s = std::isfinite(shares[i]) ? std::max(shares[i], 0.0) : 0.0;
        const double h = plot_h * s / top_share;
        svg << "<rect x=\"" << num(kLeft + bar_w * double(i)) << "\" y=\""
            << num(kTop + plot_h - h) << "\" width=\"" << num(bar_w * 0.9)
            << "\" height=\"" << num(h) << "\" fill=\"#1f77b4\"/>";
    }
    svg << "\n<line x1=\"" << kLeft << "\" y1=\"" << kTop + plot_h << "\" x2=\""
        << kLeft + plot_w << "\" y2=\"" << kTop + plot_h << "\" stroke=\"black\"/>"
        << "<line x1=\"" << kLeft << "\" y1=\"" << kTop << "\" x2=\"" << kLeft
        << "\" y2=\"" << kTop + plot_h << "\" stroke=\"black\"/>\n"
        << "<text x=\"" << kLeft - 3 << "\" y=\"" << kTop + 8
        << "\" text-anchor=\"end\" font-size=\"9\">" << std::lround(100.0 * top_share)
        << "%</text>"
        << "<text x=\"" << kLeft - 3 << "\" y=\"" << kTop + plot_h
        << "\" text-anchor=\"end\" font-size=\"9\">0</text>\n"
        << "<text x=\"" << kLeft << "\" y=\"" << kTop + plot_h + 11
        << "\" font-size=\"9\">0</text><text x=\"" << kLeft + plot_w << "\" y=\""
        << kTop + plot_h + 11 << "\" text-anchor=\"end\" font-size=\"9\">1</text>"
        << "<text x=\"" << num(kLeft + plot_w / 2) << "\" y=\"" << kHeight - 6
        << "\" text-anchor=\"middle\" font-size=\"10\">" << escape_xml(x_label)
        << "</text>\n</svg>\n";
    return svg.str();
}

std::string level_values_svg(const std::string& title,
                             const std::vector<std::string>& levels,
                             const std::vector<double>& values,
                             const std::string& x_label) {
    constexpr double kWidth = 240, kHeight = 160, kLeft = 48, kRight = 12, kTop = 22,
                     kBottom = 44;
    const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
    double lo = INFINITY, hi = -INFINITY;
    for (double v : values)
        if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    padded_range(lo, hi);
    auto y_of = [&](double v) { return kTop + plot_h * (hi - v) / (hi - lo); };
    const std::size_t n = std::max<std::size_t>(levels.size(), 1);
    auto x_of = [&](std::size_t i) {
        return kLeft + plot_w * (double(i) + 0.5) / double(n);
    };
    std::ostringstream svg;
    svg << svg_header(kWidth, kHeight);
    svg << "<text x=\"" << num(kWidth / 2) << "\" y=\"14\" text-anchor=\"middle\" "
        << "font-size=\"11\">" << escape_xml(title) << "</text>\n"
        << "<line x1=\"" << kLeft << "\" y1=\"" << kTop << "\" x2=\"" << kLeft
        << "\" y2=\"" << kTop + plot_h << "\" stroke=\"black\"/><line x1=\"" << kLeft
        << "\" y1=\"" << kTop + plot_h << "\" x2=\"" << kLeft + plot_w << "\" y2=\""
        << kTop + plot_h << "\" stroke=\"black\"/>\n";
    for (int t = 0; t <= 2; ++t) {
        const double v = lo + (hi - lo) * t / 2.0;
        svg << "<text x=\"" << kLeft - 4 << "\" y=\"" << num(y_of(v) + 3)
            << "\" text-anchor=\"end\" font-size=\"9\">" << num(v) << "</text>";
    }
    std::string points;
    for (std::size_t i = 0; i < levels.size() && i < values.size(); ++i) {
        svg << "<text x=\"" << num(x_of(i)) << "\" y=\"" << num(kTop + plot_h + 12)
            << "\" text-anchor=\"middle\" font-size=\"9\">" << escape_xml(levels[i])
            << "</text>";
        if (!std::isfinite(values[i])) continue;
        points += num(x_of(i)) + "," + num(y_of(values[i])) + " ";
        svg << "<circle cx=\"" << num(x_of(i)) << "\" cy=\"" << num(y_of(values[i]))
            << "\" r=\"3.5\" fill=\"#1f77b4\"/>";
    }
    svg << "\n<polyline points=\"" << points
        << "\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\"/>\n"
        << "<text x=\"" << num(kLeft + plot_w / 2) << "\" y=\"" << num(kHeight - 6)
        << "\" text-anchor=\"middle\" font-size=\"10\">" << escape_xml(x_label)
        << "</text>\n</svg>\n";
    return svg.str();
}

}  // namespace lucent::analysis
