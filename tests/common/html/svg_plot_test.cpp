// The stimulus-set report's small plots: bar heights proportional to the shares, one dot
// per defined value, and no NaN or Inf in the SVG text; the pieces every chart uses.
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
    EXPECT_NE(svg.find(">50%<"), std::string::npos);  // the tallest bar's share
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

TEST(SvgPieces, NumbersHaveTwoDecimalsAndRangesCanBeDrawn) {
    EXPECT_EQ(svg_number(12.5), "12.50");
    EXPECT_EQ(svg_number(-0.004), "-0.00");
    double lo = 2, hi = 4;  // padded by 5% of 2 on each side
    padded_range(lo, hi);
    EXPECT_DOUBLE_EQ(lo, 1.9);
    EXPECT_DOUBLE_EQ(hi, 4.1);
    lo = 3, hi = 3;  // one value: a unit range around it, padded
    padded_range(lo, hi);
    EXPECT_DOUBLE_EQ(lo, 2.45);
    EXPECT_DOUBLE_EQ(hi, 3.55);
    lo = INFINITY, hi = -INFINITY;  // nothing defined: [0, 1], padded
    padded_range(lo, hi);
    EXPECT_DOUBLE_EQ(lo, -0.05);
    EXPECT_DOUBLE_EQ(hi, 1.05);
    const std::string header = svg_header(200, 120);
    EXPECT_EQ(header.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\"", 0),
              0u);
    EXPECT_NE(header.find("viewBox=\"0 0 200 120\""), std::string::npos);
}

}  // namespace
}  // namespace lucent::common
