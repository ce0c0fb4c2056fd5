// Tukey HSD: the k = 2 identity with the pooled t test, R's documented warpbreaks
// example, the Tukey-Kramer standard error, and the interval/p-value agreement.
#include "analysis/stats/tukey.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <cmath>

#include "tests/analysis/stats/studentized_range_reference.h"

namespace lucent::analysis {
namespace {

OneWayData named(std::vector<std::pair<std::string, std::vector<double>>> values) {
    OneWayData data;
    for (auto& [name, v] : values) data.groups.push_back({name, std::move(v)});
    return data;
}

TEST(Tukey, TwoGroupsMatchPooledTTest) {
    // Unequal sizes: Tukey-Kramer reduces to the pooled two-sample t test when k = 2.
    const std::vector<double> a{4, 5, 6, 5, 7}, b{7, 8, 6, 9, 10, 8, 9};
    const auto data = named({{"a", a}, {"b", b}});
    const AnovaResult anova = one_way_anova(data);
    const TukeyResult r = tukey_hsd(data, anova, {0.05, true});
    ASSERT_EQ(r.pairs.size(), 1u);
    const TukeyPair& p = r.pairs[0];
    double ma = 0, mb = 0, ss = 0;
    for (double x : a) ma += x / a.size();
    for (double x : b) mb += x / b.size();
    for (double x : a) ss += (x - ma) * (x - ma);
    for (double x : b) ss += (x - mb) * (x - mb);
    const double df = a.size() + b.size() - 2.0, msw = ss / df;
    const double se_t = std::sqrt(msw * (1.0 / a.size() + 1.0 / b.size()));
    const double t = (mb - ma) / se_t;
    const boost::math::students_t dist(df);
    EXPECT_NEAR(p.diff, mb - ma, 1e-14);  // b - a, as R prints it
    EXPECT_NEAR(*p.se, se_t / std::sqrt(2.0), 1e-14);
    EXPECT_NEAR(*p.q, std::fabs(t) * std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(*p.p_adj,
                2 * boost::math::cdf(boost::math::complement(dist, std::fabs(t))), 1e-10);
    const double half = boost::math::quantile(dist, 0.975) * se_t;
    EXPECT_NEAR(*p.lower, (mb - ma) - half, 1e-8);
    EXPECT_NEAR(*p.upper, (mb - ma) + half, 1e-8);
    EXPECT_FALSE(r.hsd_05.has_value());  // unbalanced: no single HSD
}

TEST(Tukey, WarpbreaksByTensionAgainstHandMeansAndReferenceQuadrature) {
    // R's warpbreaks, breaks by tension (one-way). Means: L 655/18, M 475/18, H 390/18.
    const auto data = named(
        {{"L", {26, 30, 54, 25, 70, 52, 51, 26, 67, 27, 14, 29, 19, 29, 31, 41, 20, 44}},
         {"M", {18, 21, 29, 17, 12, 18, 35, 30, 36, 42, 26, 19, 16, 39, 28, 21, 39, 29}},
         {"H",
          {36, 21, 24, 18, 10, 43, 28, 15, 26, 20, 21, 24, 17, 13, 15, 15, 16, 28}}});
    const AnovaResult anova = one_way_anova(data);
    const TukeyResult r = tukey_hsd(data, anova, {0.05, true});
    ASSERT_EQ(r.pairs.size(), 3u);
    const double expected_diff[] = {(475.0 - 655.0) / 18, (390.0 - 655.0) / 18,
                                    (390.0 - 475.0) / 18};
    const double se = std::sqrt(*anova.ms_within / 18);
    for (int i = 0; i < 3; ++i) {
        const TukeyPair& p = r.pairs[i];
        EXPECT_NEAR(p.diff, expected_diff[i], 1e-12);
        EXPECT_NEAR(*p.se, se, 1e-12);
        // p_adj against the independent extended-precision quadrature.
        const auto ref =
            test::reference_studentized_range(std::fabs(p.diff) / se, 3, 51.0L);
        EXPECT_NEAR(*p.p_adj, static_cast<double>(ref.upper), 1e-10);
        const auto at_bound =
            test::reference_studentized_range((p.diff - *p.lower) / se, 3, 51.0L);
        EXPECT_NEAR(static_cast<double>(at_bound.upper), 0.05, 1e-9);
    }
    EXPECT_EQ(r.pairs[0].level_a, "L");
    EXPECT_EQ(r.pairs[0].level_b, "M");
    ASSERT_TRUE(r.hsd_05 && r.hsd_01);  // balanced: HSD = q_crit sqrt(MSW / n)
    EXPECT_NEAR(*r.hsd_05, r.pairs[0].diff - *r.pairs[0].lower, 1e-12);
    EXPECT_GT(*r.hsd_01, *r.hsd_05);
}

TEST(Tukey, IntervalExcludesZeroExactlyWhenSignificant) {
    const auto data = named({{"1", {3, 4, 5, 4, 3, 4}},
                             {"2", {4, 5, 6, 5, 5}},
                             {"3", {5, 6, 7, 6, 7, 6, 5}},
                             {"4", {4, 4, 5, 5}}});
    const AnovaResult anova = one_way_anova(data);
    const TukeyResult r = tukey_hsd(data, anova, {0.10, true});
    ASSERT_EQ(r.pairs.size(), 6u);
    int significant = 0;
    for (const TukeyPair& p : r.pairs) {
        const bool excludes_zero = *p.lower > 0 || *p.upper < 0;
        EXPECT_EQ(excludes_zero, *p.p_adj < 0.10) << p.level_a << "-" << p.level_b;
        significant += excludes_zero;
        // Tukey-Kramer: se from each pair's own sizes.
        const double na = data.groups[std::stoi(p.level_a) - 1].values.size();
        const double nb = data.groups[std::stoi(p.level_b) - 1].values.size();
        EXPECT_NEAR(*p.se, std::sqrt(*anova.ms_within / 2 * (1 / na + 1 / nb)), 1e-14);
    }
    EXPECT_GT(significant, 0);
    EXPECT_LT(significant, 6);
}

TEST(Tukey, DegenerateCases) {
    // Zero within variance, different means: q infinite, p 0; equal means: undefined.
    const auto flat = named({{"a", {1, 1}}, {"b", {2, 2}}, {"c", {1, 1}}});
    const TukeyResult r = tukey_hsd(flat, one_way_anova(flat));
    ASSERT_EQ(r.pairs.size(), 3u);
    EXPECT_TRUE(std::isinf(*r.pairs[0].q));
    EXPECT_EQ(*r.pairs[0].p_adj, 0.0);
    EXPECT_FALSE(r.pairs[1].q.has_value());  // a vs c: 0 / 0
    EXPECT_FALSE(r.pairs[1].p_adj.has_value());
    // One group, or no within df: a note, no pairs.
    const auto one = named({{"a", {1, 2}}});
    EXPECT_TRUE(tukey_hsd(one, one_way_anova(one)).pairs.empty());
    const auto singletons = named({{"a", {1}}, {"b", {2}}});
    EXPECT_FALSE(tukey_hsd(singletons, one_way_anova(singletons)).note.empty());
    // More than 200 groups: refused with a note.
    OneWayData many;
    for (int g = 0; g < 201; ++g)
        many.groups.push_back({std::to_string(g), {1.0 * g, g + 1.0}});
    const TukeyResult big = tukey_hsd(many, one_way_anova(many));
    EXPECT_TRUE(big.pairs.empty());
    EXPECT_NE(big.note.find("200"), std::string::npos);
}

TEST(Tukey, HundredFiftyGroupsIntervalsOnly) {
    OneWayData many;
    for (int g = 0; g < 150; ++g)
        many.groups.push_back(
            {std::to_string(g), {0.01 * g, 0.01 * g + 1, 0.01 * g + 2}});
    const TukeyResult r = tukey_hsd(many, one_way_anova(many), {0.05, false});
    EXPECT_EQ(r.pairs.size(), 150u * 149 / 2);
    for (const TukeyPair& p : r.pairs)
        ASSERT_TRUE(p.lower && *p.lower < 0 && *p.upper > 0);
}

}  // namespace
}  // namespace lucent::analysis
