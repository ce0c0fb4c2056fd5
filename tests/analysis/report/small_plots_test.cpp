// The stimulus-set report's small plots: bar heights proportional to the shares, one dot
// per defined value, and no NaN or Inf in the SVG text.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "analysis/report/svg_plot.h"

namespace lucent::analysis {
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

}  // namespace
}  // namespace lucent::analysis
