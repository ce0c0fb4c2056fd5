// One-way ANOVA: hand-computed examples and every hard case the issue names.
#include "analysis/stats/anova.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <cmath>

#include "analysis/report/format.h"
#include "analysis/stats/descriptives.h"

namespace lucent::analysis {
namespace {

OneWayData groups(std::vector<std::vector<double>> values) {
    OneWayData data;
    for (std::size_t i = 0; i < values.size(); ++i)
        data.groups.push_back({"g" + std::to_string(i + 1), std::move(values[i])});
    return data;
}

TEST(Anova, HandComputedTwoGroups) {
    // Means 2 and 5, grand mean 3.5: SSB = 3 (1.5^2) 2 = 13.5, SSW = 2 + 2 = 4.
    const AnovaResult r = one_way_anova(groups({{1, 2, 3}, {4, 5, 6}}));
    EXPECT_DOUBLE_EQ(r.ss_between, 13.5);
    EXPECT_DOUBLE_EQ(r.ss_within, 4.0);
    EXPECT_EQ(r.df_between, 1);
    EXPECT_EQ(r.df_within, 4);
    ASSERT_TRUE(r.f && r.p);
    EXPECT_DOUBLE_EQ(*r.f, 13.5);
    // F(1, 4) = T(4)^2: the p-value is the two-sided t p-value (a different Boost path).
    const double t_p = 2 * boost::math::cdf(boost::math::complement(
                               boost::math::students_t(4.0), std::sqrt(13.5)));
    EXPECT_NEAR(*r.p, t_p, 1e-14);
    EXPECT_DOUBLE_EQ(*r.eta_sq, 13.5 / 17.5);
    EXPECT_DOUBLE_EQ(*r.omega_sq, (13.5 - 1.0) / (17.5 + 1.0));
    EXPECT_TRUE(r.note.empty());
}

TEST(Anova, AllValuesIdenticalLeaveFUndefined) {
    const AnovaResult r = one_way_anova(groups({{4, 4, 4}, {4, 4}, {4, 4, 4, 4}}));
    EXPECT_FALSE(r.f.has_value());
    EXPECT_FALSE(r.p.has_value());
    EXPECT_FALSE(r.eta_sq.has_value());
    EXPECT_NE(r.note.find("undefined"), std::string::npos);
    EXPECT_EQ(format_full(r.f), "undefined");
    EXPECT_EQ(format_p_full(r.p), "undefined");
}

TEST(Anova, ZeroWithinVarianceMakesFInfinite) {
    const AnovaResult r = one_way_anova(groups({{1, 1, 1}, {2, 2, 2}}));
    ASSERT_TRUE(r.f && r.p);
    EXPECT_TRUE(std::isinf(*r.f));
    EXPECT_EQ(*r.p, 0.0);
    EXPECT_EQ(format_full(r.f), "inf");
    EXPECT_EQ(format_p_full(r.p), "< 1e-300");
    EXPECT_DOUBLE_EQ(*r.eta_sq, 1.0);
}

TEST(Anova, GroupWithOneObservation) {
    // Means 5 and 2, grand 2.75: SSB = 2.25^2 + 3 (0.75^2) = 6.75; SSW = 2; df 1, 2.
    const AnovaResult r = one_way_anova(groups({{5}, {1, 2, 3}}));
    EXPECT_DOUBLE_EQ(r.ss_between, 6.75);
    EXPECT_DOUBLE_EQ(r.ss_within, 2.0);
    EXPECT_EQ(r.df_within, 2);
    EXPECT_DOUBLE_EQ(*r.f, 6.75);
    const Descriptives d = describe(groups({{5}}).groups[0], 0.0);
    EXPECT_EQ(d.n, 1u);
    EXPECT_DOUBLE_EQ(*d.mean, 5.0);
    EXPECT_FALSE(d.sd.has_value());
    EXPECT_FALSE(d.ci_low.has_value());
}

TEST(Anova, SingleGroupAndNoWithinDf) {
    const AnovaResult single = one_way_anova(groups({{1, 2, 3}}));
    EXPECT_EQ(single.groups, 1);
    EXPECT_FALSE(single.f.has_value());
    EXPECT_FALSE(single.note.empty());
    const AnovaResult singletons = one_way_anova(groups({{1}, {2}, {3}}));
    EXPECT_FALSE(singletons.f.has_value());
    EXPECT_FALSE(singletons.ms_within.has_value());
    EXPECT_DOUBLE_EQ(singletons.ss_between, 2.0);
    EXPECT_FALSE(one_way_anova(OneWayData{}).f.has_value());
}

TEST(Anova, EmptyGroupIsLeftOut) {
    const AnovaResult with_empty = one_way_anova(groups({{}, {1, 2, 3}, {4, 5, 6}}));
    EXPECT_EQ(with_empty.groups, 2);
    EXPECT_DOUBLE_EQ(*with_empty.f, 13.5);
    const Descriptives d = describe(Group{"empty", {}}, 0.0);
    EXPECT_EQ(d.n, 0u);
    EXPECT_FALSE(d.mean.has_value());
}

TEST(Anova, HundredsOfGroups) {
    // 150 groups of {g - 1, g, g + 1}: SSW = 2 per group; SSB = 3 sum (g - 75.5)^2.
    std::vector<std::vector<double>> values;
    double expected_ssb = 0;
    for (int g = 1; g <= 150; ++g) {
        values.push_back({g - 1.0, double(g), g + 1.0});
        expected_ssb += 3.0 * (g - 75.5) * (g - 75.5);
    }
    const AnovaResult r = one_way_anova(groups(values));
    EXPECT_EQ(r.df_between, 149);
    EXPECT_EQ(r.df_within, 300);
    EXPECT_NEAR(r.ss_within, 300.0, 1e-9);
    EXPECT_NEAR(r.ss_between / expected_ssb, 1.0, 1e-14);
}

TEST(Anova, MillionObservations) {
    // 10 groups of 10^5: group g holds g -/+ 1 alternately, so SSW = 10^6 exactly and
    // SSB = 10^5 sum (g - 4.5)^2 = 8.25e6.
    std::vector<std::vector<double>> values(10);
    for (int g = 0; g < 10; ++g)
        for (int i = 0; i < 100000; ++i) values[g].push_back(g + (i % 2 ? 1.0 : -1.0));
    const AnovaResult r = one_way_anova(groups(values));
    EXPECT_NEAR(r.ss_within / 1e6, 1.0, 1e-13);
    EXPECT_NEAR(r.ss_between / 8.25e6, 1.0, 1e-13);
    EXPECT_NEAR(*r.f / ((8.25e6 / 9) / (1e6 / 999990)), 1.0, 1e-12);
    EXPECT_EQ(format_p_full(r.p), "< 1e-300");  // underflows: reported, never 0 or NaN
}

TEST(Anova, LargeOffsetKeepsDigits) {
    // Shifting by 1e9 must not change SS (two-pass, compensated).
    const AnovaResult base = one_way_anova(groups({{1.5, 2.25, 3}, {4, 5.5, 6}}));
    const AnovaResult shifted = one_way_anova(
        groups({{1e9 + 1.5, 1e9 + 2.25, 1e9 + 3}, {1e9 + 4, 1e9 + 5.5, 1e9 + 6}}));
    EXPECT_NEAR(shifted.ss_within / base.ss_within, 1.0, 1e-12);
    EXPECT_NEAR(*shifted.f / *base.f, 1.0, 1e-12);
}

}  // namespace
}  // namespace lucent::analysis
