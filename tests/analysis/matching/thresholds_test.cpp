// Thresholds (issue 31): a simulated observer with a known psychometric function
// (study/simulated_observer.h) answers the block's interleaved staircases and QUEST
// (study/adaptive/staircase_block.h); the pooled fit recovers its threshold. The hard
// cases (chance, always correct, a staircase held at the largest delta) in words.
#include "analysis/matching/thresholds.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/analysis/matching/matching_fixtures.h"

namespace lucent::analysis {
namespace {

bool any_note(const std::vector<std::string>& notes, const std::string& part) {
    for (const std::string& n : notes)
        if (n.find(part) != std::string::npos) return true;
    return false;
}

TEST(Thresholds, RecoversASimulatedObserversJnd) {
    const study::Protocol p = testing::protocol();
    // Seen half the time at delta 1: 75% correct in a pair at delta 1, the JND.
    const study::DetectionObserver observer{1.0, 0.4, 0.0};
    std::mt19937_64 rng(7);
    const auto rows = testing::simulate_staircases(p, "P1", observer, rng);
    ASSERT_EQ(rows.size(), 240u);  // three procedures of 80 trials
    ThresholdOptions options;
    options.bootstrap = 200;
    options.seed = 3;
    const ThresholdAnalysis a = analyse_thresholds(rows, &p, options);
    ASSERT_EQ(a.thresholds.size(), 1u);
    const StandardThreshold& s = a.thresholds[0];
    EXPECT_EQ(s.standard, "std1");
    EXPECT_DOUBLE_EQ(s.guess, 0.5);
    EXPECT_DOUBLE_EQ(s.p_correct, 0.75);
    ASSERT_TRUE(s.jnd && s.jnd_low && s.jnd_high) << s.jnd_text;
    EXPECT_NEAR(*s.jnd, observer.threshold, 0.25);
    EXPECT_LE(*s.jnd_low, observer.threshold);
    EXPECT_GE(*s.jnd_high, observer.threshold);
    // The standard's thickness exponent is 2: Weber fraction JND / 2.
    EXPECT_DOUBLE_EQ(*s.standard_value, 2.0);
    EXPECT_DOUBLE_EQ(*s.weber, *s.jnd / 2.0);
    // Each procedure's own estimate: 1-up/3-down converges at 79.4% correct, here
    // delta 1 + 0.4 z(0.588) = 1.09; QUEST at 82%, delta 1 + 0.4 z(0.64) = 1.14.
    ASSERT_EQ(a.tracks.size(), 3u);
    for (const StaircaseTrack& t : a.tracks) {
        ASSERT_TRUE(t.estimate) << t.label << ": " << t.estimate_text;
        EXPECT_NEAR(*t.estimate, t.method == "quest" ? 1.14 : 1.09, 0.35) << t.label;
        EXPECT_EQ(t.intensity.size(), 80u);
        if (t.method == "updown") {
            int reversals = 0;
            for (bool r : t.reversal) reversals += r ? 1 : 0;
            EXPECT_GE(reversals, 6) << t.label;
            EXPECT_NE(t.estimate_text.find("mean of the last 6 of"), std::string::npos);
        } else {
            EXPECT_NE(t.estimate_text.find("QUEST's posterior quantile"),
                      std::string::npos);
        }
        EXPECT_FALSE(t.held_at_max) << t.label;
    }
}

TEST(Thresholds, AnOddOneOutIsFittedWithAGuessRateOfAThird) {
    std::string text = testing::kProtocol;
    const std::string knob = "knob = \"thickness_exponent\"\nquestion = \"Which looks";
    text.replace(
        text.find(knob), knob.size(),
        "knob = \"thickness_exponent\"\ntrial = \"oddity\"\nquestion = \"Which looks");
    const study::Protocol p = study::parse_protocol(text, "odd.toml");
    ASSERT_EQ(p.find_block("j")->answers(), 3);
    // Seen half the time at delta 1: two thirds correct there, the odd one out's JND.
    const study::DetectionObserver observer{1.0, 0.4, 0.0};
    std::mt19937_64 rng(9);
    const auto rows = testing::simulate_staircases(p, "P1", observer, rng);
    for (const StaircaseRow& r : rows) ASSERT_TRUE(r.expected >= 1 && r.expected <= 3);
    ThresholdOptions options;
    options.bootstrap = 100;
    const StandardThreshold s = analyse_thresholds(rows, &p, options).thresholds[0];
    EXPECT_DOUBLE_EQ(s.guess, 1.0 / 3.0);
    EXPECT_DOUBLE_EQ(s.p_correct, 2.0 / 3.0);
    ASSERT_TRUE(s.jnd) << s.jnd_text;
    EXPECT_NEAR(*s.jnd, observer.threshold, 0.3);
}

TEST(Thresholds, TheWeibullFitRecoversItToo) {
    const study::Protocol p = testing::protocol();
    const study::DetectionObserver observer{1.0, 0.4, 0.0};
    std::mt19937_64 rng(11);
    const auto rows = testing::simulate_staircases(p, "P1", observer, rng);
    ThresholdOptions options;
    options.family = PsychometricFamily::weibull;
    options.bootstrap = 0;
    const ThresholdAnalysis a = analyse_thresholds(rows, &p, options);
    ASSERT_TRUE(a.thresholds[0].jnd) << a.thresholds[0].jnd_text;
    EXPECT_NEAR(*a.thresholds[0].jnd, 1.0, 0.3);
}

StaircaseRow row(double delta, bool correct, int position,
                 const std::string& label = "std1/up") {
    StaircaseRow r;
    r.participant = std::string("P");
    r.session = std::string("s");
    r.trial = position;
    r.block = std::string("j");
    r.standard = std::string("std1");
    r.staircase = label;
    r.intensity = delta;
    r.expected = 2;
    r.choice = correct ? 2 : 1;
    r.correct = correct;
    return r;
}

TEST(Thresholds, AtChanceThereIsNoThreshold) {
    const study::Protocol p = testing::protocol();
    std::mt19937_64 rng(5);
    std::vector<StaircaseRow> rows;
    for (int i = 0; i < 120; ++i)
        rows.push_back(row(0.25 * (1 + i % 10), rng() % 2 == 0, i));
    const ThresholdAnalysis a = analyse_thresholds(rows, &p, {});
    const StandardThreshold& s = a.thresholds[0];
    EXPECT_FALSE(s.jnd);
    EXPECT_EQ(s.jnd_text, "no threshold");
    EXPECT_TRUE(any_note(s.notes, "No threshold"));
    EXPECT_TRUE(any_note(s.fit.notes, "at chance")) << s.fit.notes.front();
    EXPECT_FALSE(s.weber);
}

TEST(Thresholds, AlwaysCorrectIsBelowTheSmallestDelta) {
    const study::Protocol p = testing::protocol();
    std::vector<StaircaseRow> rows;
    for (int i = 0; i < 30; ++i) rows.push_back(row(0.2 + 0.1 * (i % 5), true, i));
    const StandardThreshold s = analyse_thresholds(rows, &p, {}).thresholds[0];
    EXPECT_FALSE(s.jnd);
    EXPECT_EQ(s.jnd_text, "< 0.2");
    EXPECT_TRUE(any_note(s.notes, "below the smallest delta shown, 0.2"));
}

TEST(Thresholds, AStaircaseHeldAtTheRangesEndIsSaid) {
    const study::Protocol p = testing::protocol();
    // Wrong answers drive a 1-up staircase from 2.5 up to the block's max delta 3 and
    // hold it there.
    std::vector<StaircaseRow> rows;
    const double deltas[] = {2.5, 2.9, 3, 3, 3, 3};
    for (int i = 0; i < 6; ++i) rows.push_back(row(deltas[i], false, i));
    const ThresholdAnalysis a = analyse_thresholds(rows, &p, {});
    ASSERT_EQ(a.tracks.size(), 1u);
    EXPECT_TRUE(a.tracks[0].held_at_max);
    EXPECT_EQ(a.tracks[0].at_max, 4);
    EXPECT_TRUE(any_note(a.thresholds[0].notes,
                         "std1/up: Held at the largest delta the block allows, 3, on 4 "
                         "trials"));
    // Never a NaN: nothing is estimated.
    EXPECT_FALSE(a.thresholds[0].jnd);
}

TEST(Thresholds, ReversalEstimate) {
    EXPECT_FALSE(reversal_estimate({1.0}, 6));
    EXPECT_DOUBLE_EQ(*reversal_estimate({1.0, 3.0}, 6), 2.0);
    EXPECT_DOUBLE_EQ(*reversal_estimate({9, 1, 2, 3, 4, 5, 6}, 6), 3.5);
}

}  // namespace
}  // namespace lucent::analysis
