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
    const auto all = analyze_table(t, request).pairs;
    ASSERT_EQ(all.size(), 3u);
    EXPECT_EQ(calls, 3);
    EXPECT_EQ(all[0].question, "translucent");
    EXPECT_EQ(all[0].factor, "thickness");
    // translucent ~ thickness: {2, 3} vs {5, 6}: SSB = 9, SSW = 1, F = 18.
    EXPECT_DOUBLE_EQ(*all[0].anova.f, 18.0);
    EXPECT_EQ(all[1].missing_ratings, 1u);

    request.question = "realistic";
    EXPECT_EQ(analyze_table(t, request).pairs.size(), 1u);
    request.factor = "backlight";
    EXPECT_THROW(analyze_table(t, request), InputError);
}

TEST(AnalyzeTable, WithinSubjectLayoutUsesParticipantMeansAndLeavesOutIncompleteOnes) {
    // p1 and p2 rate both levels (p1 twice at level 18: mean 2.5); p3 rates only one.
    const LongTable t = table_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,thickness,18,q,2\np1,a2,thickness,18,q,3\np1,b,thickness,25,q,5\n"
        "p2,a,thickness,18,q,3\np2,b,thickness,25,q,7\n"
        "p3,a,thickness,18,q,4\n");
    const AnalysisResult result = analyze_table(t, AnalysisRequest{});
    ASSERT_EQ(result.pairs.size(), 1u);
    const WithinSubjectAnalysis& w = result.pairs[0].within;
    ASSERT_TRUE(w.computed) << w.note;
    EXPECT_EQ(w.participants, 2);
    EXPECT_EQ(w.excluded_participants, std::vector<std::string>{"p3"});
    // Differences 25 - 18: p1 5 - 2.5 = 2.5, p2 7 - 3 = 4: mean 3.25.
    ASSERT_EQ(w.paired.size(), 1u);
    EXPECT_DOUBLE_EQ(*w.paired[0].diff, 3.25);
    EXPECT_EQ(w.paired[0].level_a, "18");
    // Every pair is within-subject, so that is the primary design unless asked.
    EXPECT_EQ(result.primary, Design::Within);
    AnalysisRequest between;
    between.primary = Design::Between;
    EXPECT_EQ(analyze_table(t, between).primary, Design::Between);
}

TEST(AnalyzeTable, BetweenSubjectLayoutIsNotAnalysedWithinAndNamesWhy) {
    const LongTable t = table_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,f,1,q,2\np2,a,f,1,q,3\np3,b,f,2,q,5\np4,b,f,2,q,6\n");
    const AnalysisResult result = analyze_table(t, AnalysisRequest{});
    EXPECT_FALSE(result.pairs[0].within.computed);
    EXPECT_NE(result.pairs[0].within.note.find("0 participant(s) rated every level"),
              std::string::npos)
        << result.pairs[0].within.note;
    EXPECT_EQ(result.primary, Design::Between);
}

}  // namespace
}  // namespace lucent::analysis
