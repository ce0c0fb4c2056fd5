#pragma once
// Small SVG charts written as text (no plotting library) for Lucent's HTML pages: the
// pieces every chart uses (document header, coordinates, axis range) and the stimulus-set
// report's small plots. The analysis report's mean/CI charts build on the same pieces
// (analysis/report/svg_plot.h).
#include <string>
#include <vector>

namespace lucent::common {

// The opening <svg> element (width x height, sans-serif 12 px) and a white background;
// the caller closes it with "</svg>\n".
std::string svg_header(double width, double height);
// A coordinate or tick value as SVG text: two decimals ("12.50").
std::string svg_number(double x);
// A range that can be drawn from [lo, hi]: a default (0, 1) when nothing is defined
// (lo > hi, NaN), never zero-height, padded by 5% on each side.
void padded_range(double& lo, double& hi);

// Small plots for stimulus-set reports (a few hundred pixels wide):
// a histogram of `shares` (one bar per equal-width bin over [0, 1], heights are fractions
// of the pixels), titled, with the bins' range under the axis;
std::string histogram_svg(const std::string& title, const std::vector<double>& shares,
                          const std::string& x_label = "luminance");
// one value per level, as dots joined by a line, on an axis spanning the values; the
// levels' names under the axis, `x_label` (e.g. the factor) below them.
std::string level_values_svg(const std::string& title,
                             const std::vector<std::string>& levels,
                             const std::vector<double>& values,
                             const std::string& x_label = "");

}  // namespace lucent::common
