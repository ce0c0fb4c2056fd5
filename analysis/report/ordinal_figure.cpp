#include "analysis/report/ordinal_figure.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/html/html_page.h"
#include "common/html/svg_plot.h"

namespace lucent::analysis {
namespace {

// Colour of category k of n: from a warm brown (lowest rating) through a pale middle to
// a blue-green (highest), so the stack reads like a Likert bar.
std::string category_colour(std::size_t k, std::size_t n) {
    const double t = n > 1 ? double(k) / double(n - 1) : 0.5;
    const double low[3] = {166, 97, 26}, middle[3] = {245, 240, 230},
                 high[3] = {1, 133, 113};
    const double* from = t < 0.5 ? low : middle;
    const double* to = t < 0.5 ? middle : high;
    const double u = t < 0.5 ? t * 2.0 : (t - 0.5) * 2.0;
    std::ostringstream out;
    out << "rgb(";
    for (int c = 0; c < 3; ++c)
        out << int(std::lround(from[c] + (to[c] - from[c]) * u)) << (c < 2 ? "," : ")");
    return out.str();
}

// One stacked bar: segments bottom-up from the lowest category.
void stacked_bar(std::ostringstream& svg, double x, double width, double top,
                 double height, const std::vector<double>& shares) {
    double below = 0.0;
    for (std::size_t k = 0; k < shares.size(); ++k) {
        const double share =
            std::isfinite(shares[k]) ? std::clamp(shares[k], 0.0, 1.0) : 0.0;
        if (share <= 0.0) continue;
        const double y = top + height * (1.0 - std::min(1.0, below + share));
        svg << "<rect x=\"" << common::svg_number(x) << "\" y=\"" << common::svg_number(y)
            << "\" width=\"" << common::svg_number(width) << "\" height=\""
            << common::svg_number(height * share) << "\" fill=\""
            << category_colour(k, shares.size())
            << "\" stroke=\"#555\" stroke-width=\"0.5\"/>\n";
        below += share;
    }
}

// Text centred at x, squeezed (textLength) into `room` when a 7 px-per-character
// estimate says it would not fit, so nothing is drawn outside the figure.
void centred_text(std::ostringstream& svg, double x, double y, double room,
                  const std::string& text) {
    svg << "<text x=\"" << common::svg_number(x) << "\" y=\"" << common::svg_number(y)
        << "\" text-anchor=\"middle\"";
    if (7.0 * double(text.size()) > room)
        svg << " textLength=\"" << common::svg_number(room)
            << "\" lengthAdjust=\"spacingAndGlyphs\"";
    svg << ">" << common::markup_escape(text) << "</text>\n";
}

}  // namespace

std::string ordinal_probability_svg(const std::string& title, const std::string& factor,
                                    const std::vector<std::string>& levels,
                                    const std::vector<std::string>& categories,
                                    const std::vector<std::vector<double>>& predicted,
                                    const std::vector<std::vector<double>>& observed) {
    const double left = 60, right = 110, top = 40, bottom = 64, plot_height = 240;
    const double slot = 70;
    const double width = std::max(
        380.0, left + right + slot * double(std::max<std::size_t>(levels.size(), 1)));
    const double height = top + plot_height + bottom;
    std::ostringstream svg;
    svg << common::svg_header(width, height);
    centred_text(svg, width / 2, 20, width - 16, title);
    // y axis: probability 0..1
    const char* const kTickLabels[] = {"0", "0.25", "0.5", "0.75", "1"};
    for (int tick = 0; tick <= 4; ++tick) {
        const double y = top + plot_height * (1.0 - tick / 4.0);
        svg << "<line x1=\"" << left - 4 << "\" x2=\""
            << common::svg_number(width - right) << "\" y1=\"" << common::svg_number(y)
            << "\" y2=\"" << common::svg_number(y) << "\" stroke=\"#ddd\"/>\n<text x=\""
            << left - 8 << "\" y=\"" << common::svg_number(y + 4)
            << "\" text-anchor=\"end\">" << kTickLabels[tick] << "</text>\n";
    }
    svg << "<text transform=\"translate(16," << common::svg_number(top + plot_height / 2)
        << ") rotate(-90)\" text-anchor=\"middle\">probability</text>\n";
    for (std::size_t l = 0; l < levels.size(); ++l) {
        const double x = left + slot * double(l) + 10;
        if (l < predicted.size()) stacked_bar(svg, x, 34, top, plot_height, predicted[l]);
        if (l < observed.size())
            stacked_bar(svg, x + 38, 12, top, plot_height, observed[l]);
        centred_text(svg, x + 25, top + plot_height + 16, slot - 8, levels[l]);
    }
    centred_text(svg, width / 2, top + plot_height + 36, width - 16, factor);
    centred_text(svg, width / 2, top + plot_height + 54, width - 16,
                 "wide bars: the model; narrow bars: observed");
    // Legend, the highest rating on top as in the stacks.
    for (std::size_t k = 0; k < categories.size(); ++k) {
        const double y = top + 16.0 * double(categories.size() - 1 - k);
        svg << "<rect x=\"" << common::svg_number(width - right + 14) << "\" y=\""
            << common::svg_number(y) << "\" width=\"12\" height=\"12\" fill=\""
            << category_colour(k, categories.size()) << "\" stroke=\"#555\"/>\n<text x=\""
            << common::svg_number(width - right + 32) << "\" y=\""
            << common::svg_number(y + 10) << "\">rating "
            << common::markup_escape(categories[k]) << "</text>\n";
    }
    svg << "</svg>\n";
    return svg.str();
}

}  // namespace lucent::analysis
