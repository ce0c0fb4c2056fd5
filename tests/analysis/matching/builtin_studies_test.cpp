// The built-in studies of issue 31 through the analysis: `matching` (dipole targets, so
// no physical value of the empirical shader's r; the crossed-light block's constancy
// index against the same-light match, by hand on log10) and `jnd` (three standards, an
// up/down staircase and a QUEST each, answered by a simulated observer with a known
// threshold).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "analysis/matching/matching.h"
#include "analysis/matching/matching_report.h"
#include "analysis/matching/thresholds.h"
#include "tests/analysis/matching/matching_fixtures.h"

namespace lucent::analysis {
namespace {

MatchRow row(const std::string& participant, const std::string& block,
             const std::string& target, const std::string& match, double value) {
    MatchRow r = testing::match_row(participant, target, value);
    r.block = block;
    r.match = match;
    return r;
}

TEST(BuiltinStudies, MatchingCrossedLightIsComparedWithTheSameLightMatch) {
    const study::Protocol p = study::builtin_protocol("matching");
    const auto cs =
        analyse_matches({row("A", "back", "dipole_marble_back", "match_back", 10),
                         row("B", "back", "dipole_marble_back", "match_back", 12),
                         row("A", "cross", "dipole_marble_back", "match_front", 20),
                         row("B", "cross", "dipole_marble_back", "match_front", 22)},
                        &p);
    ASSERT_EQ(cs.size(), 2u);
    const ConditionMatch& back = cs[0];
    const ConditionMatch& cross = cs[1];
    // A dipole target has no value of the empirical shader's r.
    EXPECT_FALSE(back.target_value);
    EXPECT_FALSE(back.bias);
    EXPECT_FALSE(back.constancy);
    EXPECT_NE(back.constancy_text.find("share every scene factor"), std::string::npos)
        << back.constancy_text;
    // A log block's statistics are on log10: the geometric mean sqrt(10 * 12), the SD
    // of log10 10 and log10 12, |log10 12 - log10 10| / sqrt(2).
    EXPECT_TRUE(back.on_log10);
    EXPECT_NEAR(*back.mean, std::sqrt(120.0), 1e-12);
    EXPECT_NEAR(*back.sd, std::log10(1.2) / std::sqrt(2.0), 1e-14);
    // t(0.975, 1) = 12.7062047361747: the interval 10^(log10 mean -+ t SD / sqrt 2).
    const double half = 12.7062047361747 * std::log10(1.2) / 2.0;
    EXPECT_NEAR(std::log10(*back.ci_low), std::log10(std::sqrt(120.0)) - half, 1e-9);
    EXPECT_NEAR(std::log10(*back.ci_high), std::log10(std::sqrt(120.0)) + half, 1e-9);
    // Crossed light: one scene factor, light_direction; the reference is the same-light
    // match sqrt(120), the cross match sqrt(440), on log10 over the range 2.5..100.
    EXPECT_EQ(cross.factors, std::vector<std::string>{"light_direction"});
    EXPECT_EQ(cross.constancy_factor, "light_direction");
    ASSERT_TRUE(cross.constancy_reference && cross.constancy) << cross.constancy_text;
    EXPECT_NEAR(*cross.constancy_reference, std::sqrt(120.0), 1e-12);
    const double reference = std::log10(std::sqrt(120.0));
    const double expected =
        1.0 - (std::log10(std::sqrt(440.0)) - reference) /
                  std::max(reference - std::log10(2.5), 2.0 - reference);
    EXPECT_NEAR(*cross.constancy, expected, 1e-12);
    EXPECT_NE(cross.constancy_text.find("against the same-scene match in block back"),
              std::string::npos)
        << cross.constancy_text;
    // The crossed-light block is plotted against the same-light match, the same-light
    // block by target name.
    const MatchingSection section = matching_section(cs, {});
    std::string plots;
    for (const Block& b : section.blocks)
        if (b.kind == Block::kPlot) plots += b.svg;
    EXPECT_NE(plots.find("same-scene match (line: equal)"), std::string::npos)
        << plots.substr(0, 4000);
    // Without the same-light block there is no reference: said in words.
    const auto alone =
        analyse_matches({row("A", "cross", "dipole_marble_back", "match_front", 20)}, &p);
    EXPECT_FALSE(alone[0].constancy);
    EXPECT_NE(
        alone[0].constancy_text.find("no block matches this target in the same scene"),
        std::string::npos)
        << alone[0].constancy_text;
}

TEST(BuiltinStudies, JndRecoversEachStandardsThresholdOfASimulatedObserver) {
    const study::Protocol p = study::builtin_protocol("jnd");
    // Seen half the time at a change of 5 in r: 75% correct at delta 5.
    const study::DetectionObserver observer{5.0, 2.0, 0.0};
    std::vector<StaircaseRow> rows;
    std::mt19937_64 rng(21);
    for (const std::string participant : {"P1", "P2", "P3"}) {
        const auto r = testing::simulate_staircases(p, participant, observer, rng, "jnd");
        rows.insert(rows.end(), r.begin(), r.end());
    }
    ThresholdOptions options;
    options.bootstrap = 100;
    const ThresholdAnalysis a = analyse_thresholds(rows, &p, options);
    ASSERT_EQ(a.thresholds.size(), 9u);  // 3 participants x 3 standards
    ASSERT_EQ(a.tracks.size(), 18u);     // and 2 procedures each
    double sum = 0;
    int estimated = 0;
    for (const StandardThreshold& s : a.thresholds) {
        ASSERT_TRUE(s.standard_value);
        if (!s.jnd) continue;
        ++estimated;
        sum += *s.jnd;
        EXPECT_NEAR(*s.jnd, observer.threshold, 3.0)
            << s.participant << " " << s.standard;
        EXPECT_DOUBLE_EQ(*s.weber, *s.jnd / *s.standard_value);
    }
    // Every standard: a participant above chance has a threshold even where the rise
    // over the track's deltas is not significant (checked over seeds 1..12 as well).
    EXPECT_EQ(estimated, 9);
    EXPECT_NEAR(sum / estimated, observer.threshold, 1.0);
}

}  // namespace
}  // namespace lucent::analysis
