#pragma once
// SVG charts written as text (no plotting library), the one plotting code of Lucent's
// pages: the bench plots (lucent bench accuracy), the analysis report's mean/CI figures
// and the stimulus-set report's small plots. Every axis has round tick values (1-2-5
// steps, or decades on a log axis, chosen where positive data span more than two
// decades); panels wrap into a grid of at most `max_columns` columns, so a figure fits
// a page; text that would not fit its room is squeezed into it (SVG textLength), so
// nothing is drawn outside the viewBox.
#include <optional>
#include <string>
#include <vector>

namespace lucent::common {

// The opening <svg> element (width x height, sans-serif 12 px) and a white background;
// the caller closes it with "</svg>\n".
std::string svg_header(double width, double height);
// A coordinate as SVG text: two decimals ("12.50").
std::string svg_number(double x);

// ---- Axes -------------------------------------------------------------------------

enum class AxisScale {
    automatic,  // log where every value is positive and max / min > log_ratio
    linear,
    log,  // values <= 0 are left out, with a note; none positive: linear, with a note
};

struct AxisOptions {
    AxisScale scale = AxisScale::automatic;
    int max_ticks = 6;          // at most this many ticks on a linear axis
    bool include_zero = false;  // a linear axis reaches 0 (times, errors)
    // automatic: log beyond this ratio of the largest to the smallest value (two
    // decades; errors, compared by their order, may ask for one)
    double log_ratio = 100.0;
};

// A drawn axis: its range [lo, hi] (on a log axis the values themselves, decades at both
// ends), its ticks inside the range with their labels, and what was left out.
struct Axis {
    double lo = 0.0, hi = 1.0;
    bool log = false;
    std::vector<double> ticks;
    std::vector<std::string> labels;  // one per tick: "0.25", "1e-5", "0.001", "7"
    std::string note;  // e.g. "1 value not finite left out"; empty when none was

    // Where `v` lies along the axis, 0 at lo and 1 at hi (log-spaced on a log axis);
    // NaN for a value a log axis cannot show (<= 0).
    double fraction(double v) const;
};

// The axis for `values`: NaN and infinite values are left out (and counted in the
// note). Linear: a 1-2-5 step giving at most max_ticks ticks, the range widened to
// whole steps; one value (zero span) gets +-10% of itself (+-1 for 0); no values, [0, 1].
// Log: the range from the decade at or below the smallest value to the one at or above
// the largest, a tick at each decade (every 2nd, 3rd, ... beyond 6 decades; 2 and 5
// between decades when the range is at most 2 decades).
Axis choose_axis(const std::vector<double>& values, const AxisOptions& options = {});
// A linear axis over exactly [lo, hi] (a rating scale: 1..7), ticks at 1-2-5 steps
// inside it, at least 1 apart when `integer_steps`.
Axis fixed_axis(double lo, double hi, int max_ticks = 8, bool integer_steps = false);
// The 1-2-5 step at or above `raw` (> 0): 0.013 -> 0.02, 7 -> 10.
double nice_step(double raw);

// ---- Figures of panels --------------------------------------------------------------

// One panel: points (x, y) on numeric axes, or one value per category (`categories`
// non-empty: x is ignored), optionally with an interval [y_low, y_high] per point (a
// 95% CI: drawn as a bar with caps; where the y axis ends inside it, the bar stops at
// the axis with a triangle pointing on). NaN values are not drawn.
// One labelled curve among several in a panel (every technique's error against time),
// drawn in its own colour and named in the panel's legend.
struct PlotSeries {
    std::string label;
    std::vector<double> x, y;
};

struct PlotPanel {
    std::string title, x_label, y_label;
    std::vector<double> x, y;
    std::vector<std::string> categories;
    std::vector<double> y_low, y_high;      // empty, or one per point
    std::vector<std::string> point_labels;  // text beside each point; empty: none
    // Per point (empty: none): drawn as an open circle (an adaptive track's wrong
    // answers, the correct ones filled), and ringed by a larger circle (its reversals).
    std::vector<bool> open_points, ringed_points;
    bool join = true;  // a line through the points in order
    AxisOptions x_axis, y_axis;
    std::optional<Axis> fixed_y;  // this y axis instead of one chosen from the data
    // Further curves on the same numeric axes (the axes cover them too), each a line
    // through its points in order, with a legend.
    std::vector<PlotSeries> series;
    // The series are details of the main curve (each participant's scale under the
    // pooled one): drawn first, thin and faint, in the colours after the main curve's
    // blue, and the main curve thicker over them; `main_label` names it in the legend.
    bool series_behind = false;
    std::string main_label;
};

struct FigureLayout {
    double panel_width = 320, panel_height = 260;
    int max_columns = 3;  // panels wrap into rows beyond this
};

// A figure: its title (bold, centred; none when empty) above the panels in a grid.
std::string figure_svg(const std::string& title, const std::vector<PlotPanel>& panels,
                       const FigureLayout& layout = {});

// Small plots for stimulus-set reports (a few hundred pixels wide):
// a histogram of `shares` (one bar per equal-width bin over [0, 1], heights are fractions
// of the pixels, on a percent axis), titled;
std::string histogram_svg(const std::string& title, const std::vector<double>& shares,
                          const std::string& x_label = "luminance");
// one value per level, as dots joined by a line; the levels' names under the axis,
// `x_label` (e.g. the factor) below them.
std::string level_values_svg(const std::string& title,
                             const std::vector<std::string>& levels,
                             const std::vector<double>& values,
                             const std::string& x_label = "");

}  // namespace lucent::common
