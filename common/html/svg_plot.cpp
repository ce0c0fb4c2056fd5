// Small SVG charts (see svg_plot.h).
#include "common/html/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/html/html_page.h"

namespace lucent::common {

std::string svg_number(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f", x);
    return buffer;
}

void padded_range(double& lo, double& hi) {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12 * std::max(1.0, std::fabs(hi))) lo -= 0.5, hi += 0.5;
    const double pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
}

std::string svg_header(double width, double height) {
    std::ostringstream svg;
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
        << height << "\" viewBox=\"0 0 " << width << ' ' << height
        << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    return svg.str();
}

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
    svg << "<text x=\"" << svg_number(kWidth / 2) << "\" y=\"14\" text-anchor=\"middle\" "
        << "font-size=\"11\">" << markup_escape(title) << "</text>\n";
    const double bar_w = plot_w / double(std::max<std::size_t>(shares.size(), 1));
    for (std::size_t i = 0; i < shares.size(); ++i) {
        const double s = std::isfinite(shares[i]) ? std::max(shares[i], 0.0) : 0.0;
        const double h = plot_h * s / top_share;
        svg << "<rect x=\"" << svg_number(kLeft + bar_w * double(i)) << "\" y=\""
            << svg_number(kTop + plot_h - h) << "\" width=\"" << svg_number(bar_w * 0.9)
            << "\" height=\"" << svg_number(h) << "\" fill=\"#1f77b4\"/>";
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
        << "<text x=\"" << svg_number(kLeft + plot_w / 2) << "\" y=\"" << kHeight - 6
        << "\" text-anchor=\"middle\" font-size=\"10\">" << markup_escape(x_label)
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
    svg << "<text x=\"" << svg_number(kWidth / 2) << "\" y=\"14\" text-anchor=\"middle\" "
        << "font-size=\"11\">" << markup_escape(title) << "</text>\n"
        << "<line x1=\"" << kLeft << "\" y1=\"" << kTop << "\" x2=\"" << kLeft
        << "\" y2=\"" << kTop + plot_h << "\" stroke=\"black\"/><line x1=\"" << kLeft
        << "\" y1=\"" << kTop + plot_h << "\" x2=\"" << kLeft + plot_w << "\" y2=\""
        << kTop + plot_h << "\" stroke=\"black\"/>\n";
    for (int t = 0; t <= 2; ++t) {
        const double v = lo + (hi - lo) * t / 2.0;
        svg << "<text x=\"" << kLeft - 4 << "\" y=\"" << svg_number(y_of(v) + 3)
            << "\" text-anchor=\"end\" font-size=\"9\">" << svg_number(v) << "</text>";
    }
    std::string points;
    for (std::size_t i = 0; i < levels.size() && i < values.size(); ++i) {
        svg << "<text x=\"" << svg_number(x_of(i)) << "\" y=\""
            << svg_number(kTop + plot_h + 12)
            << "\" text-anchor=\"middle\" font-size=\"9\">" << markup_escape(levels[i])
            << "</text>";
        if (!std::isfinite(values[i])) continue;
        points += svg_number(x_of(i)) + "," + svg_number(y_of(values[i])) + " ";
        svg << "<circle cx=\"" << svg_number(x_of(i)) << "\" cy=\""
            << svg_number(y_of(values[i])) << "\" r=\"3.5\" fill=\"#1f77b4\"/>";
    }
    svg << "\n<polyline points=\"" << points
        << "\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\"/>\n"
        << "<text x=\"" << svg_number(kLeft + plot_w / 2) << "\" y=\""
        << svg_number(kHeight - 6) << "\" text-anchor=\"middle\" font-size=\"10\">"
        << markup_escape(x_label) << "</text>\n</svg>\n";
    return svg.str();
}

}  // namespace lucent::common
