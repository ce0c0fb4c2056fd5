#include "report/svg_plot.h"

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
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string num(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f", x);
    return buffer;
}

}  // namespace

std::string mean_ci_plot_svg(const std::string& title, const std::string& y_label,
                             const std::vector<Descriptives>& levels) {
    constexpr double kWidth = 480, kHeight = 320, kLeft = 60, kRight = 20, kTop = 40,
                     kBottom = 60;
    // Vertical range: every mean and CI end that is defined, padded by 5%.
    double lo = INFINITY, hi = -INFINITY;
    for (const Descriptives& d : levels) {
        for (const Statistic& v : {d.mean, d.ci_low, d.ci_high})
            if (v && std::isfinite(*v)) {
                lo = std::min(lo, *v);
                hi = std::max(hi, *v);
            }
    }
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12 * std::max(1.0, std::fabs(hi))) lo -= 0.5, hi += 0.5;
    const double pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
    const double plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
    auto y_of = [&](double v) { return kTop + plot_h * (hi - v) / (hi - lo); };
    const std::size_t n = std::max<std::size_t>(levels.size(), 1);
    auto x_of = [&](std::size_t i) { return kLeft + plot_w * (i + 0.5) / n; };

    std::ostringstream svg;
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidth << "\" height=\""
        << kHeight << "\" viewBox=\"0 0 " << kWidth << ' ' << kHeight
        << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
        << "<text x=\"" << kWidth / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">"
        << escape_xml(title) << "</text>\n"
        << "<line x1=\"" << kLeft << "\" y1=\"" << kTop << "\" x2=\"" << kLeft << "\" y2=\""
        << kTop + plot_h << "\" stroke=\"black\"/>\n"
        << "<line x1=\"" << kLeft << "\" y1=\"" << kTop + plot_h << "\" x2=\"" << kLeft + plot_w
        << "\" y2=\"" << kTop + plot_h << "\" stroke=\"black\"/>\n";
    // Five ticks on the y axis.
    for (int t = 0; t <= 4; ++t) {
        const double v = lo + (hi - lo) * t / 4.0;
        svg << "<line x1=\"" << kLeft - 4 << "\" y1=\"" << num(y_of(v)) << "\" x2=\"" << kLeft
            << "\" y2=\"" << num(y_of(v)) << "\" stroke=\"black\"/>"
            << "<text x=\"" << kLeft - 6 << "\" y=\"" << num(y_of(v) + 4)
            << "\" text-anchor=\"end\">" << num(v) << "</text>\n";
    }
    svg << "<text x=\"14\" y=\"" << kTop + plot_h / 2 << "\" text-anchor=\"middle\" "
        << "transform=\"rotate(-90 14 " << kTop + plot_h / 2 << ")\">" << escape_xml(y_label)
        << "</text>\n";
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const Descriptives& d = levels[i];
        const double x = x_of(i);
        svg << "<text x=\"" << num(x) << "\" y=\"" << kTop + plot_h + 18
            << "\" text-anchor=\"middle\">" << escape_xml(d.level) << "</text>\n";
        if (d.ci_low && d.ci_high) {
            svg << "<line x1=\"" << num(x) << "\" y1=\"" << num(y_of(*d.ci_low)) << "\" x2=\""
                << num(x) << "\" y2=\"" << num(y_of(*d.ci_high)) << "\" stroke=\"#444\"/>";
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
    svg << "<text x=\"" << kLeft + plot_w / 2 << "\" y=\"" << kHeight - 12
        << "\" text-anchor=\"middle\">level (mean with 95% CI)</text>\n</svg>\n";
    return svg.str();
}

}  // namespace lucent::analysis
