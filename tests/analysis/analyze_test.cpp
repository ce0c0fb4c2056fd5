// The entry point from a long table: filters, progress callback, missing ratings, and a
// clear error when nothing matches.
#include "analyze.h"

#include <gtest/gtest.h>

#include <sstream>

namespace lucent::analysis {
namespace {

LongTable table_of(const std::string& csv) {
    std::istringstream in(csv);
    return read_long_csv(in, "t.csv", RatingScale{});
}

TEST(AnalyzeTable, OnePairPerQuestionAndFactor) {
    const LongTable t = table_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,thickness,18,translucent,2\np1,b,thickness,25,translucent,5\n"
        "p2,a,thickness,18,translucent,3\np2,b,thickness,25,translucent,6\n"
        "p1,a,thickness,18,realistic,4\np1,b,thickness,25,realistic,\n"
        "p2,a,thickness,18,realistic,5\np2,b,thickness,25,realistic,4\n"
        "p1,c,backlight,0.8,translucent,4\np1,d,backlight,1.6,translucent,6\n");
    int calls = 0;
    AnalysisRequest request;
    request.on_pair = [&](const std::string&, const std::string&, std::size_t) {
        ++calls;
    };
    const auto all = analyze_table(t, request);
    ASSERT_EQ(all.size(), 3u);
    EXPECT_EQ(calls, 3);
    EXPECT_EQ(all[0].question, "translucent");
    EXPECT_EQ(all[0].factor, "thickness");
    // translucent ~ thickness: {2, 3} vs {5, 6}: SSB = 9, SSW = 1, F = 18.
    EXPECT_DOUBLE_EQ(*all[0].anova.f, 18.0);
    EXPECT_EQ(all[1].missing_ratings, 1u);

    request.question = "realistic";
    EXPECT_EQ(analyze_table(t, request).size(), 1u);
    request.factor = "backlight";
    EXPECT_THROW(analyze_table(t, request), InputError);
}

}  // namespace
}  // namespace lucent::analysis
