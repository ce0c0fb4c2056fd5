// Kruskal-Wallis against the alternative (variance-of-ranks) formula with ranks counted
// by brute force; Welch's ANOVA against Welch's two-sample t test for k = 2.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <random>

#include "analysis/stats/anova.h"
#include "analysis/stats/kruskal_wallis.h"

namespace lucent::analysis {
namespace {

OneWayData groups(std::vector<std::vector<double>> values) {
    OneWayData data;
    for (std::size_t i = 0; i < values.size(); ++i)
        data.groups.push_back({"g" + std::to_string(i + 1), std::move(values[i])});
    return data;
}

// H = (N - 1) sum n_i (Rbar_i - Rbar)^2 / sum (R_ij - Rbar)^2, with mid-ranks counted as
// (#smaller) + (#equal + 1) / 2. This form includes the tie correction by construction.
double h_by_rank_variance(const std::vector<std::vector<double>>& values) {
    std::vector<double> all;
    for (const auto& g : values) all.insert(all.end(), g.begin(), g.end());
    auto rank = [&](double x) {
        double smaller = 0, equal = 0;
        for (double y : all) smaller += y < x, equal += y == x;
        return smaller + (equal + 1) / 2;
    };
    const double n = all.size(), mean_rank = (n + 1) / 2;
    double between = 0, total = 0;
    for (const auto& g : values) {
        double sum = 0;
        for (double x : g) {
            sum += rank(x);
            total += (rank(x) - mean_rank) * (rank(x) - mean_rank);
        }
        between += g.size() * std::pow(sum / g.size() - mean_rank, 2);
    }
    return (n - 1) * between / total;
}

TEST(KruskalWallis, NoTiesTextbook) {
    // Ranks: g1 {1,2,3} g2 {4,5,6}: H = 12/(6*7) (36/3 + 225/3) - 21 = 3.857142857...
    const auto r = kruskal_wallis(groups({{1, 2, 3}, {4, 5, 6}}));
    ASSERT_TRUE(r.h && r.p);
    EXPECT_NEAR(*r.h, 27.0 / 7.0, 1e-13);
    EXPECT_EQ(r.df, 1);
    // chi-square(1) tail = erfc(sqrt(H / 2)).
    EXPECT_NEAR(*r.p, std::erfc(std::sqrt(27.0 / 14.0)), 1e-13);
}

TEST(KruskalWallis, LikertTiesMatchRankVarianceFormula) {
    std::mt19937 engine(3);
    std::uniform_int_distribution<int> rating(1, 7);
    for (int trial = 0; trial < 5; ++trial) {
        std::vector<std::vector<double>> values(4);
        for (int g = 0; g < 4; ++g)
            for (int i = 0; i < 10 + 3 * g; ++i)
                values[g].push_back(rating(engine) + (g == 3));
        const auto r = kruskal_wallis(groups(values));
        ASSERT_TRUE(r.h);
        EXPECT_NEAR(*r.h, h_by_rank_variance(values), 1e-10);
    }
}

TEST(KruskalWallis, ManyDistinctValuesWithTiesMatchRankVarianceFormula) {
    // Values that are not whole numbers: the ranks come from one sort of the pooled
    // values.
    std::mt19937 engine(5);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::vector<std::vector<double>> values(4);
    for (int g = 0; g < 4; ++g)
        for (int i = 0; i < 60; ++i)
            values[g].push_back(std::round(20 * (normal(engine) + 0.2 * g)) / 20);
    const auto r = kruskal_wallis(groups(values));
    ASSERT_TRUE(r.h);
    EXPECT_NEAR(*r.h, h_by_rank_variance(values), 1e-10);
}

TEST(KruskalWallis, WholeNumbersNarrowOrWideMatchRankVarianceFormula) {
    // Negative whole numbers with ties (counted in a histogram), and whole numbers spread
    // wider than the histogram's span (sorted), against the brute-force ranks.
    std::mt19937 engine(11);
    for (const int spread : {9, 100000}) {
        std::uniform_int_distribution<int> value(-spread, spread);
        std::vector<std::vector<double>> values(3);
        for (int g = 0; g < 3; ++g)
            for (int i = 0; i < 40 + 5 * g; ++i)
                values[g].push_back(value(engine) + 2 * g);
        const auto r = kruskal_wallis(groups(values));
        ASSERT_TRUE(r.h) << spread;
        EXPECT_NEAR(*r.h, h_by_rank_variance(values), 1e-10) << spread;
    }
}

TEST(KruskalWallis, AllTiedIsUndefined) {
    const auto r = kruskal_wallis(groups({{3, 3}, {3, 3, 3}}));
    EXPECT_FALSE(r.h.has_value());
    EXPECT_FALSE(r.p.has_value());
    EXPECT_FALSE(r.note.empty());
    EXPECT_FALSE(kruskal_wallis(groups({{1, 2}})).h.has_value());  // one group
}

TEST(Welch, TwoGroupsEqualWelchTTestSquared) {
    const std::vector<double> a{3.1, 4.7, 2.2, 5.0, 3.8, 4.1}, b{6.2, 5.1, 7.7, 9.4, 4.8};
    auto mean_var = [](const std::vector<double>& x) {
        double m = 0, v = 0;
        for (double y : x) m += y;
        m /= x.size();
        for (double y : x) v += (y - m) * (y - m);
        return std::pair{m, v / (x.size() - 1)};
    };
    const auto [ma, va] = mean_var(a);
    const auto [mb, vb] = mean_var(b);
    const double ua = va / a.size(), ub = vb / b.size();
    const double t = (ma - mb) / std::sqrt(ua + ub);
    const double df =
        (ua + ub) * (ua + ub) / (ua * ua / (a.size() - 1) + ub * ub / (b.size() - 1));
    const WelchResult r = welch_anova(groups({a, b}));
    ASSERT_TRUE(r.f && r.df2 && r.p);
    EXPECT_NEAR(*r.f, t * t, 1e-12 * t * t);
    EXPECT_EQ(*r.df1, 1.0);
    EXPECT_NEAR(*r.df2, df, 1e-10 * df);
    const double p_t = 2 * boost::math::cdf(boost::math::complement(
                               boost::math::students_t(df), std::fabs(t)));
    EXPECT_NEAR(*r.p, p_t, 1e-12);
}

TEST(Welch, EqualVariancesBalancedIsNearClassicalF) {
    // With equal n and equal sample variances the weights are equal and Welch's F equals
    // the classical F divided by its correction B = 1 + 2(k-2)/(k^2-1) * lambda.
    const auto data = groups({{1, 2, 3}, {2, 3, 4}, {4, 5, 6}});
    const WelchResult w = welch_anova(data);
    const AnovaResult a = one_way_anova(data);
    const double k = 3, n = 3, lambda = k * std::pow(1 - 1 / k, 2) / (n - 1);
    EXPECT_NEAR(*w.f, *a.f / (1 + 2 * (k - 2) / (k * k - 1) * lambda), 1e-12);
    EXPECT_NEAR(*w.df2, (k * k - 1) / (3 * lambda), 1e-12);
}

TEST(Welch, UndefinedCases) {
    EXPECT_FALSE(welch_anova(groups({{1, 2, 3}, {5}})).f.has_value());  // n = 1
    EXPECT_FALSE(
        welch_anova(groups({{1, 2, 3}, {5, 5}})).f.has_value());   // zero variance
    EXPECT_FALSE(welch_anova(groups({{1, 2, 3}})).f.has_value());  // one group
}

}  // namespace
}  // namespace lucent::analysis
