// Matching (issue 31): the statistics of the confirmed match values worked by hand (the
// t quantile from tables: t(0.975, 3) = 3.182446305284263), the constancy index's
// closed form, and the hard cases said in words.
#include "analysis/matching/matching.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/analysis/matching/matching_fixtures.h"

namespace lucent::analysis {
namespace {

using testing::match_row;

const ConditionMatch& find(const std::vector<ConditionMatch>& cs,
                           const std::string& target) {
    for (const ConditionMatch& c : cs)
        if (c.target == target) return c;
    throw std::runtime_error("no condition " + target);
}

TEST(Matching, MeansSdsAndIntervalsWorkedByHand) {
    const study::Protocol p = testing::protocol();
    // front: 1, 2, 3, 4 from two participants (A: 1, 3; B: 2, 4).
    const std::vector<MatchRow> rows = {
        match_row("A", "front", 1), match_row("B", "front", 2),
        match_row("A", "front", 3), match_row("B", "front", 4)};
    const auto cs = analyse_matches(rows, &p);
    ASSERT_EQ(cs.size(), 1u);
    const ConditionMatch& c = cs[0];
    EXPECT_EQ(c.n, 4);
    EXPECT_DOUBLE_EQ(*c.mean, 2.5);
    // SD = sqrt((1.5^2 + 0.5^2 + 0.5^2 + 1.5^2) / 3) = sqrt(5/3).
    EXPECT_NEAR(*c.sd, std::sqrt(5.0 / 3.0), 1e-14);
    const double half = 3.182446305284263 * std::sqrt(5.0 / 3.0) / 2.0;
    EXPECT_NEAR(*c.ci_low, 2.5 - half, 1e-9);
    EXPECT_NEAR(*c.ci_high, 2.5 + half, 1e-9);
    // Participant means 2 and 3: mean 2.5, SD sqrt(0.5), t(0.975, 1) = 12.7062047361747.
    ASSERT_EQ(c.participants.size(), 2u);
    EXPECT_EQ(c.participants[0].participant, "A");
    EXPECT_DOUBLE_EQ(c.participants[0].mean, 2.0);
    EXPECT_DOUBLE_EQ(c.participants[1].mean, 3.0);
    EXPECT_NEAR(*c.participant_ci_high - 2.5,
                12.7062047361747 * std::sqrt(0.5) / std::sqrt(2.0), 1e-8);
    // The target's own value 2: bias 0.5, its interval the mean's shifted by 2.
    EXPECT_DOUBLE_EQ(*c.target_value, 2.0);
    EXPECT_DOUBLE_EQ(*c.bias, 0.5);
    EXPECT_NEAR(*c.bias_ci_low, 0.5 - half, 1e-9);
    EXPECT_NEAR(*c.bias_ci_high, 0.5 + half, 1e-9);
    // One factor apart (backlight 1.2 against 0.6): 1 - 0.5 / max(2 - 0, 10 - 2).
    EXPECT_EQ(c.constancy_factor, "backlight");
    EXPECT_DOUBLE_EQ(*c.constancy, 1.0 - 0.5 / 8.0);
    EXPECT_TRUE(c.notes.empty());
}

TEST(Matching, ConstancyIndexClosedForm) {
    EXPECT_DOUBLE_EQ(*constancy_index(2.0, 2.0, 0, 10), 1.0);
    EXPECT_DOUBLE_EQ(*constancy_index(10.0, 2.0, 0, 10),
                     0.0);  // as far as the range allows
    EXPECT_DOUBLE_EQ(*constancy_index(1.0, 2.0, 0, 10), 1.0 - 1.0 / 8.0);
    EXPECT_DOUBLE_EQ(*constancy_index(7.0, 8.0, 0, 10), 1.0 - 1.0 / 8.0);
    // Log scale: on log10, a factor 10 off over the decades 0.01..100 (room 2).
    EXPECT_NEAR(*constancy_index(10.0, 1.0, 0.01, 100, true), 0.5, 1e-15);
    EXPECT_FALSE(constancy_index(1.0, 0.0, 0.0, 10, true));  // log of 0
    EXPECT_FALSE(constancy_index(1.0, 1.0, 1.0, 1.0));       // no room
}

TEST(Matching, SaysWhyThereIsNoIndex) {
    const study::Protocol p = testing::protocol();
    const auto cs = analyse_matches(
        {match_row("A", "two_factors", 2.5), match_row("A", "two_factors", 3),
         match_row("A", "picture", 4), match_row("A", "picture", 5)},
        &p);
    const ConditionMatch& two = find(cs, "two_factors");
    EXPECT_FALSE(two.constancy);
    EXPECT_NE(
        two.constancy_text.find("differ in 2 scene factors (backlight, diffuse_weight)"),
        std::string::npos)
        << two.constancy_text;
    EXPECT_DOUBLE_EQ(*two.bias, 0.75);  // the target value is known all the same
    const ConditionMatch& picture = find(cs, "picture");
    EXPECT_FALSE(picture.target_value);
    EXPECT_FALSE(picture.bias);
    EXPECT_EQ(picture.constancy_text, "no constancy index: the target is a picture");
}

TEST(Matching, HardCasesInWords) {
    const study::Protocol p = testing::protocol();
    // n = 1: no SD, no interval.
    auto cs = analyse_matches({match_row("A", "front", 2.5)}, &p);
    EXPECT_EQ(cs[0].n, 1);
    EXPECT_FALSE(cs[0].sd);
    EXPECT_FALSE(cs[0].ci_low);
    ASSERT_EQ(cs[0].notes.size(), 1u);
    EXPECT_EQ(cs[0].notes[0], "One match only: no SD and no interval.");
    // Zero variance: SD 0, the interval one point.
    cs = analyse_matches({match_row("A", "front", 3), match_row("B", "front", 3)}, &p);
    EXPECT_EQ(*cs[0].sd, 0.0);
    EXPECT_EQ(*cs[0].ci_low, 3.0);
    EXPECT_EQ(*cs[0].ci_high, 3.0);
    EXPECT_NE(cs[0].notes[0].find("Every match was the same value"), std::string::npos);
    // Every match at the range's upper end.
    cs = analyse_matches({match_row("A", "front", 10), match_row("B", "front", 10)}, &p);
    EXPECT_TRUE(cs[0].all_at_range_end);
    bool said = false;
    for (const auto& n : cs[0].notes)
        said = said ||
               n.find("Every match is at the range's upper end, 10") != std::string::npos;
    EXPECT_TRUE(said);
    // Without the protocol: the statistics, no target value, no index, no NaN.
    cs = analyse_matches({match_row("A", "front", 1), match_row("A", "front", 2)},
                         nullptr);
    EXPECT_DOUBLE_EQ(*cs[0].mean, 1.5);
    EXPECT_FALSE(cs[0].target_value);
    EXPECT_FALSE(cs[0].constancy);
    EXPECT_FALSE(cs[0].constancy_text.empty());
}

}  // namespace
}  // namespace lucent::analysis
