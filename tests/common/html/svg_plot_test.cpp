// The one plotting code: the stimulus-set report's small plots (bar heights proportional
// to the shares, one dot per defined value, no NaN or Inf in the SVG text), the tick
// chooser (round 1-2-5 steps covering the data, log decades, degenerate inputs, fixed
// rating scales) and figures of panels wrapping into a grid.
#include "common/html/svg_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "common/html/html_page.h"

namespace lucent::common {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
        ++n;
    return n;
}

TEST(SmallPlots, HistogramBarsAreProportionalToTheShares) {
    const std::string svg = histogram_svg("h", {0.5, 0.25, 0.0, 0.25});
    std::vector<double> heights;
    const std::regex bar(
        "<rect x=\"[0-9.]+\" y=\"[0-9.]+\" width=\"[0-9.]+\" height=\"([0-9.]+)\"");
    for (std::sregex_iterator it(svg.begin(), svg.end(), bar), end; it != end; ++it)
        heights.push_back(std::stod((*it)[1]));
    ASSERT_EQ(heights.size(), 4u);
    EXPECT_GT(heights[0], 0.0);
    EXPECT_NEAR(heights[1], heights[0] / 2, 0.01);
    EXPECT_EQ(heights[2], 0.0);
    EXPECT_NEAR(heights[3], heights[0] / 2, 0.01);
    // A percent axis at round steps over the tallest bar (50%: 0, 20, 40, 60%), and the
    // bins' range 0, 0.5, 1 under it.
    for (const char* tick : {">0%<", ">20%<", ">40%<", ">60%<", ">0<", ">0.5<", ">1.0<"})
        EXPECT_NE(svg.find(tick), std::string::npos) << tick;
}

TEST(SmallPlots, LevelValuesSkipUndefinedValuesAndNameTheAxis) {
    const std::string svg = level_values_svg("RMS contrast", {"18", "25", "30"},
                                             {0.7, NAN, 1.2}, "thickness_exponent");
    EXPECT_EQ(count(svg, "<circle"), 2u);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_EQ(svg.find("inf"), std::string::npos);
    EXPECT_NE(svg.find(">thickness_exponent<"), std::string::npos);
    EXPECT_NE(svg.find(">25<"), std::string::npos);
    // Nothing defined, or one value: still a drawable axis.
    const std::string flat = level_values_svg("x", {"a"}, {1.0});
    EXPECT_EQ(flat.find("nan"), std::string::npos);
    EXPECT_EQ(count(level_values_svg("x", {"a", "b"}, {NAN, NAN}), "<circle"), 0u);
    EXPECT_EQ(markup_escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
}

TEST(Figures, OpenAndRingedPointsMarkAnAdaptiveTrack) {
    // Five trials: the 2nd and 4th wrong (open), the 3rd a reversal (ringed).
    PlotPanel p;
    p.x = {1, 2, 3, 4, 5};
    p.y = {1, 0.8, 0.9, 0.7, 0.8};
    p.open_points = {false, true, false, true, false};
    p.ringed_points = {false, false, true, false, false};
    const std::string svg = figure_svg("", {p});
    EXPECT_EQ(count(svg, "fill=\"white\" stroke=\"#1f77b4\""), 2u);
    EXPECT_EQ(count(svg, "r=\"6.5\""), 1u);
    // Without them every point is filled and none is ringed.
    p.open_points.clear();
    p.ringed_points.clear();
    const std::string plain = figure_svg("", {p});
    EXPECT_EQ(count(plain, "fill=\"white\" stroke="), 0u);
    EXPECT_EQ(count(plain, "r=\"6.5\""), 0u);
}

TEST(SvgPieces, NumbersHaveTwoDecimalsAndTheHeaderItsViewBox) {
    EXPECT_EQ(svg_number(12.5), "12.50");
    EXPECT_EQ(svg_number(-0.004), "-0.00");
    const std::string header = svg_header(200, 120);
    EXPECT_EQ(header.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\"", 0),
              0u);
    EXPECT_NE(header.find("viewBox=\"0 0 200 120\""), std::string::npos);
}

std::vector<std::string> labels_of(const Axis& axis) { return axis.labels; }
using Labels = std::vector<std::string>;

TEST(AxisTicks, NiceStepsAreOneTwoOrFiveTimesAPowerOfTen) {
    EXPECT_DOUBLE_EQ(nice_step(0.013), 0.02);
    EXPECT_DOUBLE_EQ(nice_step(7), 10);
    EXPECT_DOUBLE_EQ(nice_step(1), 1);
    EXPECT_DOUBLE_EQ(nice_step(0.3), 0.5);
    EXPECT_DOUBLE_EQ(nice_step(2.5), 5);
    EXPECT_DOUBLE_EQ(nice_step(100), 100);
    EXPECT_DOUBLE_EQ(nice_step(0.0011), 0.002);
}

TEST(AxisTicks, LinearTicksAreRoundAndCoverTheData) {
    // The analysis report's old axis ran from -4.68 to 12.01 with ticks at quarters of
    // it; the same data now get steps of 5.
    const Axis a = choose_axis({-4.68, 12.01});
    EXPECT_FALSE(a.log);
    EXPECT_EQ(labels_of(a), (Labels{"-5", "0", "5", "10", "15"}));
    EXPECT_DOUBLE_EQ(a.lo, -5);
    EXPECT_DOUBLE_EQ(a.hi, 15);
    EXPECT_EQ(labels_of(choose_axis({0.013, 0.047})),
              (Labels{"0.01", "0.02", "0.03", "0.04", "0.05"}));
    EXPECT_EQ(labels_of(choose_axis({0.37, 4.2})),
              (Labels{"0", "1", "2", "3", "4", "5"}));
    // Errors and times reach 0.
    EXPECT_EQ(labels_of(choose_axis({0.6, 0.9}, {AxisScale::linear, 6, true})),
              (Labels{"0", "0.2", "0.4", "0.6", "0.8", "1.0"}));
    // Any range: ticks k * step (step 1, 2 or 5 times a power of ten), at most
    // max_ticks of them, the first at or below the smallest value and the last at or
    // above the largest; each label reads back as its tick.
    unsigned seed = 12345;
    const auto next = [&] {
        seed = seed * 1103515245u + 12345u;
        return double((seed >> 8) & 0xffff) / 65535.0;
    };
    for (int i = 0; i < 500; ++i) {
        const double scale = std::pow(10.0, std::floor(next() * 12.0) - 6.0);
        const double a0 = (next() - 0.5) * 10.0 * scale, a1 = a0 + next() * 10.0 * scale;
        const int max_ticks = 3 + i % 6;
        const Axis axis = choose_axis({a0, a1}, {AxisScale::linear, max_ticks, false});
        ASSERT_GE(axis.ticks.size(), 2u);
        ASSERT_LE(axis.ticks.size(), std::size_t(max_ticks)) << a0 << " " << a1;
        EXPECT_LE(axis.lo, std::min(a0, a1));
        EXPECT_GE(axis.hi, std::max(a0, a1));
        EXPECT_DOUBLE_EQ(axis.ticks.front(), axis.lo);
        EXPECT_DOUBLE_EQ(axis.ticks.back(), axis.hi);
        const double step = axis.ticks[1] - axis.ticks[0];
        const double mantissa =
            step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
        EXPECT_TRUE(std::fabs(mantissa - 1) < 1e-6 || std::fabs(mantissa - 2) < 1e-6 ||
                    std::fabs(mantissa - 5) < 1e-6)
            << step;
        for (std::size_t t = 0; t < axis.ticks.size(); ++t) {
            EXPECT_NEAR(std::fmod(std::fabs(axis.ticks[t]) / step + 0.5, 1.0), 0.5, 1e-6);
            EXPECT_NEAR(std::stod(axis.labels[t]), axis.ticks[t], step * 1e-6)
                << axis.labels[t];
        }
    }
}

TEST(AxisTicks, ALogAxisIsChosenWherePositiveDataSpanMoreThanTwoDecades) {
    const Axis a = choose_axis({2e-4, 3e-3, 0.15});  // 750:1
    EXPECT_TRUE(a.log);
    EXPECT_DOUBLE_EQ(a.lo, 1e-4);
    EXPECT_DOUBLE_EQ(a.hi, 1);
    EXPECT_EQ(labels_of(a), (Labels{"1e-4", "0.001", "0.01", "0.1", "1"}));
    EXPECT_NEAR(a.fraction(1e-2), 0.5, 1e-12);
    EXPECT_TRUE(std::isnan(a.fraction(-1)));
    EXPECT_FALSE(choose_axis({0.01, 0.5}).log);  // 50:1
    AxisOptions errors;
    errors.log_ratio = 10;  // bench accuracy's errors: log beyond one decade
    EXPECT_TRUE(choose_axis({0.01, 0.5}, errors).log);
    EXPECT_FALSE(choose_axis({0.01, 0.09}, errors).log);
    EXPECT_FALSE(choose_axis({0.0, 1e-4, 1.0}).log);  // a zero: linear
    // Up to two decades, 2 and 5 between them; beyond six, every other decade.
    EXPECT_EQ(labels_of(choose_axis({0.03, 0.2}, {AxisScale::log})),
              (Labels{"0.01", "0.02", "0.05", "0.1", "0.2", "0.5", "1"}));
    EXPECT_EQ(labels_of(choose_axis({1e-9, 1e3})),
              (Labels{"1e-9", "1e-7", "1e-5", "0.001", "0.1", "10", "1000"}));
    // A power of ten alone: its decade and the next.
    EXPECT_EQ(labels_of(choose_axis({100}, {AxisScale::log})),
              (Labels{"100", "200", "500", "1000"}));
}

TEST(AxisTicks, DegenerateInputsStillGiveADrawableAxisAndSayWhatWasLeftOut) {
    const Axis one = choose_axis({3});  // one value: +-10% of it
    EXPECT_LT(one.lo, 3);
    EXPECT_GT(one.hi, 3);
    EXPECT_EQ(labels_of(one), (Labels{"2.6", "2.8", "3.0", "3.2", "3.4"}));
    EXPECT_EQ(labels_of(choose_axis({0, 0})),
              (Labels{"-1.0", "-0.5", "0", "0.5", "1.0"}));
    EXPECT_EQ(labels_of(choose_axis({0}, {AxisScale::linear, 6, true})),
              (Labels{"0", "0.2", "0.4", "0.6", "0.8", "1.0"}));
    const Axis none = choose_axis({});
    EXPECT_DOUBLE_EQ(none.lo, 0);
    EXPECT_DOUBLE_EQ(none.hi, 1);
    EXPECT_TRUE(none.note.empty());
    const Axis odd = choose_axis({NAN, INFINITY, 2, 4, -INFINITY});
    EXPECT_EQ(odd.note, "3 values not finite left out");
    EXPECT_EQ(labels_of(odd), (Labels{"2.0", "2.5", "3.0", "3.5", "4.0"}));
    const Axis negative = choose_axis({-1, 0, 0.5, 20}, {AxisScale::log});
    EXPECT_TRUE(negative.log);
    EXPECT_EQ(negative.note, "2 values <= 0 left out of the log axis");
    EXPECT_DOUBLE_EQ(negative.lo, 0.1);
    EXPECT_DOUBLE_EQ(negative.hi, 100);
    const Axis no_positive = choose_axis({-1, 0}, {AxisScale::log});
    EXPECT_FALSE(no_positive.log);
    EXPECT_NE(no_positive.note.find("no positive value: linear axis"), std::string::npos);
    for (const Axis& axis : {one, none, odd, negative, no_positive})
        for (const auto& label : axis.labels) {
            EXPECT_EQ(label.find("nan"), std::string::npos);
            EXPECT_EQ(label.find("inf"), std::string::npos);
        }
}

TEST(AxisTicks, AFixedAxisKeepsItsRangeWithIntegerTicksOnARatingScale) {
    const Axis rating = fixed_axis(1, 7, 8, true);
    EXPECT_DOUBLE_EQ(rating.lo, 1);
    EXPECT_DOUBLE_EQ(rating.hi, 7);
    EXPECT_EQ(labels_of(rating), (Labels{"1", "2", "3", "4", "5", "6", "7"}));
    EXPECT_EQ(labels_of(fixed_axis(1, 2, 8, true)), (Labels{"1", "2"}));
    EXPECT_EQ(labels_of(fixed_axis(0, 100, 8, true)),
              (Labels{"0", "20", "40", "60", "80", "100"}));
    EXPECT_EQ(labels_of(fixed_axis(0, 1, 3)), (Labels{"0", "0.5", "1.0"}));
}

TEST(Figures, PanelsWrapIntoRowsOfThreeAndLongTitlesAreSqueezedIntoTheWidth) {
    std::vector<PlotPanel> panels(5);
    for (std::size_t i = 0; i < panels.size(); ++i) {
        panels[i].title = "knob " + std::to_string(i);
        panels[i].x = {0.5, 1.0, 2.0};
        panels[i].y = {1e-4, 1e-3, 0.2};
    }
    const std::string title(200, 'W');
    const std::string svg = figure_svg(title, panels);
    EXPECT_NE(svg.find("width=\"960\" height=\"546\""), std::string::npos) << svg;
    EXPECT_NE(svg.find("textLength=\"952.00\""), std::string::npos);
    EXPECT_EQ(count(svg, "<circle"), 15u);
    // Each panel's error axis is logarithmic, with decade labels.
    EXPECT_EQ(count(svg, ">1e-4<"), 5u);
    EXPECT_EQ(count(svg, ">0.001<"), 5u);
    // An interval beyond a fixed axis stops at it with a triangle.
    PlotPanel rating;
    rating.categories = {"a", "b"};
    rating.y = {2, 6.5};
    rating.y_low = {1.5, 5};
    rating.y_high = {2.5, 9};
    rating.fixed_y = fixed_axis(1, 7, 8, true);
    const std::string clipped = figure_svg("", {rating});
    EXPECT_EQ(count(clipped, "<path"), 1u);
    EXPECT_EQ(clipped.find("nan"), std::string::npos);
}

// Several labelled curves in one panel (bench fidelity: every technique's error against
// time): each its own colour and polyline, named in the legend, and the axes cover every
// curve's points.
TEST(Figures, SeriesShareThePanelsAxesWithALegend) {
    PlotPanel panel;
    panel.x_axis.scale = AxisScale::log;
    panel.series = {{"empirical", {2.0, 3.0}, {12.0, 11.0}},
                    {"dipole", {40.0, 900.0}, {6.0, 5.5}},
                    {"path", {1500.0, 30000.0}, {4.0, NAN}}};
    const std::string svg = figure_svg("", {panel});
    EXPECT_EQ(count(svg, "<polyline"), 3u);
    EXPECT_EQ(count(svg, "<circle"), 5u);  // the NaN point is not drawn
    for (const char* label : {">empirical<", ">dipole<", ">path<"})
        EXPECT_EQ(count(svg, label), 1u) << label;
    for (const char* colour : {"#1f77b4", "#ff7f0e", "#2ca02c"})
        EXPECT_NE(svg.find(colour), std::string::npos) << colour;
    // The log x axis runs from the decade below 2 to the one above 30000.
    EXPECT_NE(svg.find(">1<"), std::string::npos);
    EXPECT_NE(svg.find(">1e5<"), std::string::npos) << svg;
    EXPECT_EQ(svg.find("nan"), std::string::npos);
}

TEST(Figures, SeriesBehindTheMainCurveAreFaintAndTheMainCurveLeadsTheLegend) {
    PlotPanel panel;
    panel.x = {1.0, 2.0, 3.0};
    panel.y = {0.0, 0.5, 1.0};
    panel.series = {{"P1", {1.0, 2.0, 3.0}, {0.0, 0.4, 1.0}},
                    {"P2", {1.0, 2.0, 3.0}, {0.0, 0.7, 1.0}}};
    panel.series_behind = true;
    panel.main_label = "pooled";
    const std::string svg = figure_svg("", {panel});
    // Three lines: the two series first (faint, no dots), then the main curve over them.
    EXPECT_EQ(count(svg, "<polyline"), 3u);
    EXPECT_EQ(count(svg, "stroke-opacity=\"0.55\""), 2u);
    EXPECT_LT(svg.find("stroke-opacity"), svg.find("stroke-width=\"2.5\""));
    EXPECT_EQ(count(svg, "<circle"), 3u);  // the main curve's points only
    // Legend: pooled in the main curve's blue, then P1 and P2 in the next colours.
    EXPECT_LT(svg.find(">pooled<"), svg.find(">P1<"));
    EXPECT_LT(svg.find(">P1<"), svg.find(">P2<"));
    EXPECT_EQ(count(svg, "stroke=\"#1f77b4\" stroke-width=\"1\""),
              0u);                                               // no series in blue
    EXPECT_NE(svg.find("fill=\"#ff7f0e\""), std::string::npos);  // P1's legend swatch
    // Ten participants: the colours wrap round without the main curve's blue.
    panel.series.clear();
    for (int k = 0; k < 10; ++k)
        panel.series.push_back({"P" + std::to_string(k), {1.0, 2.0}, {0.1 * k, 0.2}});
    const std::string many = figure_svg("", {panel});
    EXPECT_EQ(count(many, "fill=\"#1f77b4\"/>"), 1u + 3u);  // the swatch and 3 dots
}

}  // namespace
}  // namespace lucent::common
