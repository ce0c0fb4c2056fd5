// The entry point from a long table: filters, progress callback, missing ratings, and a
// clear error when nothing matches.
#include "analysis/analyze.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "analysis/report/report.h"
#include "tests/support/test_paths.h"

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

// Each mixed-model fit is announced before and reported after, numbered over the run's
// fits (lmm before clmm within a pair), with its pair's ratings; after the last, none is
// left. A pair the models cannot fit (one rating per level) is reported as not fitted.
TEST(AnalyzeTable, MixedModelProgressCountsEveryFitBeforeAndAfter) {
    const LongTable t = table_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,thickness,18,translucent,2\np1,b,thickness,25,translucent,5\n"
        "p2,a,thickness,18,translucent,3\np2,b,thickness,25,translucent,6\n"
        "p3,a,thickness,18,translucent,3\np3,b,thickness,25,translucent,4\n"
        "p1,a,thickness,18,realistic,4\np1,b,thickness,25,realistic,5\n");
    AnalysisRequest request;
    request.models = parse_model_list("anova,lmm,clmm", "anova");
    std::vector<ModelFitProgress> seen;
    request.on_fit = [&](const ModelFitProgress& p) { seen.push_back(p); };
    analyze_table(t, request);
    ASSERT_EQ(seen.size(), 8u);  // 2 pairs x 2 models, each before and after
    for (std::size_t i = 0; i < seen.size(); ++i) {
        const ModelFitProgress& p = seen[i];
        EXPECT_EQ(p.index, static_cast<int>(i / 2) + 1);
        EXPECT_EQ(p.total, 4);
        EXPECT_EQ(p.done, i % 2 == 1);
        EXPECT_EQ(p.model, (i / 2) % 2 == 0 ? "clmm" : "lmm");  // in registry order
        EXPECT_EQ(p.question, i < 4 ? "translucent" : "realistic");
        EXPECT_EQ(p.factor, "thickness");
        EXPECT_EQ(p.ratings, i < 4 ? 6u : 2u);
        if (p.done) {
            EXPECT_GE(p.seconds, 0.0);
            EXPECT_GE(p.elapsed, p.seconds);
            EXPECT_GE(p.left, 0.0);
            EXPECT_EQ(p.fitted, i < 4) << i;
        }
    }
    EXPECT_EQ(seen.back().left, 0.0);

    request.models = parse_model_list("anova", "anova");
    seen.clear();
    analyze_table(t, request);
    EXPECT_TRUE(seen.empty());
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
    // p3 rated one level only: 2 of 3 participants complete is not a within design
    // (issue 26 item 4), unless a share of two thirds is stated.
    EXPECT_EQ(result.primary, Design::Between);
    AnalysisRequest two_thirds;
    two_thirds.within_share = 2.0 / 3.0;
    EXPECT_EQ(analyze_table(t, two_thirds).primary, Design::Within);
    AnalysisRequest between;
    between.primary = Design::Between;
    EXPECT_EQ(analyze_table(t, between).primary, Design::Between);
}

TEST(AnalyzeTable, EveryParticipantRatingEveryLevelIsWithin) {
    const LongTable t = table_of(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,f,1,q,2\np1,b,f,2,q,5\np2,a,f,1,q,3\np2,b,f,2,q,7\n"
        "p3,a,f,1,q,1\np3,b,f,2,q,4\n");
    const AnalysisResult result = analyze_table(t, AnalysisRequest{});
    EXPECT_EQ(result.primary, Design::Within);
    EXPECT_NE(result.primary_reason.find("3 of 3 participants"), std::string::npos)
        << result.primary_reason;
}

// Issue 26 item 4: 12 participants of whom 10 rated one level each. The old rule ("every
// pair has at least two complete participants") called this within and ran the
// repeated-measures ANOVA on 2 participants; it is between, and the summary says how
// many participants and ratings each test used.
TEST(AnalyzeTable, TwelveParticipantsOfWhomTenRatedOneLevelEachAreNotWithin) {
    std::string csv = "participant,stimulus,factor,level,question,rating\n";
    // p1, p2: both levels; p3..p7 level 1 only; p8..p12 level 2 only: 4 + 10 = 14
    // ratings.
    csv += "p1,a,f,1,q,2\np1,b,f,2,q,5\np2,a,f,1,q,3\np2,b,f,2,q,6\n";
    for (int i = 3; i <= 12; ++i)
        csv += "p" + std::to_string(i) + (i <= 7 ? ",a,f,1,q," : ",b,f,2,q,") +
               std::to_string(1 + i % 7) + "\n";
    const LongTable t = table_of(csv);
    const AnalysisResult result = analyze_table(t, AnalysisRequest{});
    ASSERT_EQ(result.pairs.size(), 1u);
    const OneWayAnalysis& a = result.pairs[0];
    EXPECT_EQ(a.within.participants, 2);
    EXPECT_EQ(pair_participants(a), 12);
    EXPECT_EQ(pair_ratings(a), 14u);
    EXPECT_EQ(result.primary, Design::Between);
    EXPECT_NE(result.primary_reason.find(
                  "only 2 of 12 participants rated every level of q ~ f"),
              std::string::npos)
        << result.primary_reason;

    const auto dir = test::scratch_dir("analyze_twelve_participants");
    ReportOptions options;
    options.csv = options.html = false;
    options.primary = result.primary;
    options.primary_reason = result.primary_reason;
    write_report(result.pairs, dir, options);
    std::ifstream in(dir / "report.md");
    const std::string md((std::istreambuf_iterator<char>(in)),
                         std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("Primary design: between"), std::string::npos) << md;
    EXPECT_EQ(md.find("every participant rated every level"), std::string::npos) << md;
    EXPECT_NE(md.find("| q ~ f | between (primary) | one-way ANOVA |"), std::string::npos)
        << md;
    EXPECT_NE(md.find("| 12 participants, 14 ratings |"), std::string::npos) << md;
    EXPECT_NE(md.find("| 2 of 12 participants complete |"), std::string::npos) << md;

    // A stated share decides: 2 of 12 meets one sixth, not one fifth.
    AnalysisRequest sixth;
    sixth.within_share = 1.0 / 6.0;
    EXPECT_EQ(analyze_table(t, sixth).primary, Design::Within);
    AnalysisRequest fifth;
    fifth.within_share = 0.2;
    EXPECT_EQ(analyze_table(t, fifth).primary, Design::Between);
}

// Issue 26 item 10: ratings near 1e150 (--scale any) are analysed, every number finite.
// Levels {1, 3} x 1e150 and {5, 7} x 1e150: means 2e150 and 6e150; in units of 1e300,
// SSB = 2 (2^2) + 2 (2^2) = 16 on 1 df, SSW = 4 on 2 df, F = 16 / 2 = 8.
TEST(AnalyzeTable, HugeFiniteRatingsOnScaleAnyGiveFiniteResults) {
    std::istringstream in(
        "participant,stimulus,factor,level,question,rating\n"
        "p1,a,f,1,q,1e150\np2,a,f,1,q,3e150\np3,b,f,2,q,5e150\np4,b,f,2,q,7e150\n");
    const LongTable t = read_long_csv(in, "huge.csv", RatingScale{true});
    const AnalysisResult result = analyze_table(t, AnalysisRequest{});
    const OneWayAnalysis& a = result.pairs.at(0);
    ASSERT_EQ(a.descriptives.size(), 2u);
    EXPECT_NEAR(*a.descriptives[0].mean / 2e150, 1.0, 1e-12);
    EXPECT_NEAR(*a.descriptives[1].mean / 6e150, 1.0, 1e-12);
    ASSERT_TRUE(a.anova.f.has_value());
    EXPECT_NEAR(*a.anova.f, 8.0, 1e-9);
    const auto dir = test::scratch_dir("analyze_huge_finite");
    ReportOptions options;
    options.primary = result.primary;
    for (const auto& file : write_report(result.pairs, dir, options)) {
        std::ifstream f(file);
        const std::string text((std::istreambuf_iterator<char>(f)),
                               std::istreambuf_iterator<char>());
        EXPECT_FALSE(std::regex_search(text, std::regex("nan|inf", std::regex::icase)))
            << file;
    }
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
