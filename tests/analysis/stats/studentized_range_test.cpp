// The studentized range distribution against an independent extended-precision
// quadrature (studentized_range_reference.h), the closed form for k = 2 through Student's
// t (df 1..1e9, q up to 1e17), published table values, identities (cdf + upper = 1,
// monotone, the density integrating to 1 and matching the CDF's slope, continuity where
// df switches to infinity), the quantile's round trip, and thread safety.
#include "analysis/stats/studentized_range.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <boost/math/special_functions/beta.hpp>
#include <boost/math/special_functions/erf.hpp>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include "tests/analysis/stats/studentized_range_reference.h"

namespace lucent::analysis {
namespace {

constexpr double kInf = kInfiniteDf;

// k = 2: Q = sqrt(2) |T| with T ~ t(df), so P(Q > q) = 2 P(T > q / sqrt 2).
double upper_k2(double q, double df) {
    if (std::isinf(df)) return std::erfc(0.5 * q);
    return 2.0 * boost::math::cdf(boost::math::complement(boost::math::students_t(df),
                                                          q / std::sqrt(2.0)));
}

// k = 2 in closed form through the incomplete beta function, both tails, each from the
// form that keeps its digits: with t = q / sqrt 2 and x = t^2,
//   P(|T| > t) = I_{df/(df+x)}(df/2, 1/2) = 1 - I_{x/(df+x)}(1/2, df/2).
// Forming df/(df+x) loses the small argument's digits when x < df, and x/(df+x) when
// x > df, so each tail is taken from the small argument (ibeta or ibetac).
struct ExactTails {
    double lower, upper;
};
// The larger tail is 1 minus the smaller one (Boost's ibetac(1/2, 1/2, 2e-20) returns 1,
// 9e-11 off).
ExactTails exact_k2(double q, double df) {
    if (std::isinf(df)) return {std::erf(0.5 * q), std::erfc(0.5 * q)};
    const double x = 0.5 * q * q;
    ExactTails t{};
    if (x > df) {
        const double small = df / (df + x);
        t = {boost::math::ibetac(0.5 * df, 0.5, small),
             boost::math::ibeta(0.5 * df, 0.5, small)};
    } else {
        const double small = x / (df + x);
        t = {boost::math::ibeta(0.5, 0.5 * df, small),
             boost::math::ibetac(0.5, 0.5 * df, small)};
    }
    if (t.upper < 0.5)
        t.lower = 1.0 - t.upper;
    else
        t.upper = 1.0 - t.lower;
    return t;
}

bool long_tests() { return std::getenv("LUCENT_FULL_GRID") != nullptr; }

TEST(StudentizedRange, TwoGroupsExactFromTinyToHugeQ) {
    // The far tails: at df = 1 the upper tail falls only like 1/q, down to 1e-17 at
    // q = 1e17; at large df it underflows (1e-300 and below) long before.
    const double dfs[] = {1, 1.5, 2, 3, 4.5, 7, 10, 33, 100, 1e3, 1e4, 1e6, 1e9, kInf};
    const double per_decade = long_tests() ? 40 : 8;
    double worst_abs = 0, worst_rel = 0, worst_rel_tiny = 0;
    int checked_tiny = 0;
    for (double df : dfs)
        for (double e = -3; e <= 17 + 1e-9; e += 1.0 / per_decade) {
            const double q = std::pow(10.0, e);
            const ExactTails exact = exact_k2(q, df);
            const double upper = studentized_range_upper(q, 2, df);
            const double cdf = studentized_range_cdf(q, 2, df);
            const double abs_error =
                std::max(std::fabs(upper - exact.upper), std::fabs(cdf - exact.lower));
            worst_abs = std::max(worst_abs, abs_error);
            EXPECT_LT(abs_error, 1e-9) << "df=" << df << " q=" << q;
            const double rel =
                exact.upper > 0 ? std::fabs(upper / exact.upper - 1.0) : 0.0;
            if (exact.upper >= 1e-15) {
                worst_rel = std::max(worst_rel, rel);
                EXPECT_LT(rel, 1e-6) << "df=" << df << " q=" << q << ": " << upper
                                     << " vs " << exact.upper;
            } else if (exact.upper >= 1e-300) {
                ++checked_tiny;
                worst_rel_tiny = std::max(worst_rel_tiny, rel);
                EXPECT_LT(rel, 1e-3) << "df=" << df << " q=" << q << ": " << upper
                                     << " vs " << exact.upper;
            } else {
                EXPECT_LT(upper, 1e-290) << "df=" << df << " q=" << q;
            }
            // The lower tail keeps its digits too (q small).
            if (exact.lower >= 1e-300 && exact.lower < 0.5)
                EXPECT_NEAR(cdf / exact.lower, 1.0, 1e-9) << "df=" << df << " q=" << q;
        }
    EXPECT_GT(checked_tiny, 50);
    std::printf(
        "[ EXACT    ] k=2 worst abs %.2e, rel %.2e (tails >= 1e-15), %.2e (to 1e-300)\n",
        worst_abs, worst_rel, worst_rel_tiny);
}

// The grid: k <= 100, df >= 2 (and infinity), 0 < q <= 100. The default run
// checks every (k, df) at a rotating subset of q; LUCENT_FULL_GRID=1 checks all of them.
const double kGridQ[] = {0.05, 0.5, 1.5, 3.0, 4.5, 6.0, 10.0, 30.0, 100.0};

struct GridCase {
    int k;
    double df;
};

class RangeGrid : public ::testing::TestWithParam<GridCase> {};

TEST_P(RangeGrid, CdfAndUpperTailMatchIndependentQuadrature) {
    const auto [k, df] = GetParam();
    const bool full = long_tests();
    double worst_abs = 0.0;
    int index = 0;
    for (double q : kGridQ) {
        // Default: two or three q per case, rotating with (k, df) so that together the
        // cases cover every q; q = 100 (the huge-q tail) for k = 3 and k = 100.
        const int rotation = (k + static_cast<int>(std::isinf(df) ? 7 : df)) % 4;
        const bool huge_q_case = q == 100.0 && (k == 3 || k == 100);
        if (!full && (index++ % 4) != rotation && !huge_q_case) continue;
        const auto ref =
            test::reference_studentized_range(q, k, std::isinf(df) ? INFINITY : df);
        const double cdf = studentized_range_cdf(q, k, df);
        const double upper = studentized_range_upper(q, k, df);
        const double abs_error = std::fabs(cdf - static_cast<double>(ref.lower));
        worst_abs = std::max(worst_abs, abs_error);
        EXPECT_LT(abs_error, 1e-9) << "k=" << k << " df=" << df << " q=" << q;
        EXPECT_LT(std::fabs(upper - static_cast<double>(ref.upper)), 1e-9);
        // Tails keep their digits: relative accuracy wherever the tail is representable.
        if (ref.upper > 1e-300L) {
            EXPECT_NEAR(upper / static_cast<double>(ref.upper), 1.0, 1e-7)
                << "upper tail k=" << k << " df=" << df << " q=" << q << ": " << upper
                << " vs " << static_cast<double>(ref.upper);
        }
        if (ref.lower > 1e-300L && ref.lower < 0.5L) {
            EXPECT_NEAR(cdf / static_cast<double>(ref.lower), 1.0, 1e-7);
        }
    }
    std::printf("[ GRID     ] k=%d df=%g worst |cdf - reference| = %.2e\n", k, df,
                worst_abs);
}

std::vector<GridCase> grid_cases() {
    std::vector<GridCase> cases;
    for (int k : {2, 3, 5, 10, 20, 50, 100})
        for (double df : {2.0, 3.0, 10.0, 50.0, 1000.0, kInf}) cases.push_back({k, df});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(Grid, RangeGrid, ::testing::ValuesIn(grid_cases()),
                         [](const auto& info) {
                             const double df = info.param.df;
                             return "k" + std::to_string(info.param.k) + "_df" +
                                    (std::isinf(df)
                                         ? std::string("inf")
                                         : std::to_string(static_cast<int>(df)));
                         });

TEST(StudentizedRange, TwoGroupsFollowStudentT) {
    for (double df : {2.0, 3.0, 7.5, 30.0, 1e4, kInf})
        for (double q : {0.01, 0.3, 1.0, 2.77, 5.0, 12.0}) {
            const double expected = upper_k2(q, df);
            EXPECT_NEAR(studentized_range_upper(q, 2, df), expected,
                        1e-12 + 1e-10 * expected)
                << "df=" << df << " q=" << q;
            EXPECT_NEAR(studentized_range_cdf(q, 2, df), 1.0 - expected, 1e-12);
        }
    // df = 2 in closed form: P(Q > q) = 1 - q / sqrt(4 + q^2).
    EXPECT_NEAR(studentized_range_upper(1.5, 2, 2.0), 0.4, 1e-13);
}

TEST(StudentizedRange, FarTailIsTinyNotZero) {
    // k = 2 tails through erfc and Student's t, down past 1e-15.
    for (double q : {12.0, 16.0, 20.0, 40.0}) {
        const double expected = std::erfc(0.5 * q);
        const double upper = studentized_range_upper(q, 2, kInf);
        ASSERT_GT(upper, 0.0) << "q=" << q;
        EXPECT_NEAR(upper / expected, 1.0, 1e-9) << "q=" << q;
    }
    EXPECT_LT(upper_k2(16.0, kInf), 1e-15);  // the check above reached below 1e-15
    const double t_tail = upper_k2(60.0, 200.0);
    EXPECT_NEAR(studentized_range_upper(60.0, 2, 200.0) / t_tail, 1.0, 1e-8);
    // Larger k: positive, below 1e-15, and consistent with the reference.
    const double upper = studentized_range_upper(16.0, 10, 100.0);
    const auto ref = test::reference_studentized_range(16.0L, 10, 100.0L);
    EXPECT_GT(upper, 0.0);
    EXPECT_LT(upper, 1e-15);
    EXPECT_NEAR(upper / static_cast<double>(ref.upper), 1.0, 1e-7);
}

TEST(StudentizedRange, PublishedTableValues) {
    // Critical values q(.05) and q(.01) from standard tables (3 decimals).
    EXPECT_NEAR(studentized_range_quantile_upper(0.05, 3, 10.0), 3.877, 5e-4);
    EXPECT_NEAR(studentized_range_quantile_upper(0.05, 10, kInf), 4.474, 5e-4);
    EXPECT_NEAR(studentized_range_quantile_upper(0.01, 3, kInf), 4.120, 5e-4);
    EXPECT_NEAR(studentized_range_quantile_upper(0.05, 5, 20.0), 4.232, 5e-4);
}

TEST(StudentizedRange, QuantileInvertsTheUpperTail) {
    for (int k : {2, 10, 200})
        for (double df : {2.0, 40.0, kInf})
            for (double p : {0.9, 0.01, 1e-6}) {
                const double q = studentized_range_quantile_upper(p, k, df);
                EXPECT_NEAR(studentized_range_upper(q, k, df), p,
                            1e-9 * std::max(p, 1e-3))
                    << "k=" << k << " df=" << df << " p=" << p;
            }
    // k = 2, df = 2 in closed form: P(Q > 1.5) = 0.4.
    EXPECT_NEAR(studentized_range_quantile_upper(0.4, 2, 2.0), 1.5, 1e-10);
}

TEST(StudentizedRange, EdgesAndBadArguments) {
    EXPECT_EQ(studentized_range_cdf(0.0, 5, 10.0), 0.0);
    EXPECT_EQ(studentized_range_upper(0.0, 5, 10.0), 1.0);
    EXPECT_EQ(studentized_range_upper(INFINITY, 5, 10.0), 0.0);
    EXPECT_GT(studentized_range_cdf(1e-3, 2, 2.0), 0.0);
    // Huge df behaves like infinity.
    EXPECT_NEAR(studentized_range_cdf(3.5, 4, 1e13), studentized_range_cdf(3.5, 4, kInf),
                1e-12);
    EXPECT_NEAR(studentized_range_cdf(3.5, 4, 1e7), studentized_range_cdf(3.5, 4, kInf),
                1e-6);
    // k up to 200.
    const double q200 = studentized_range_quantile_upper(0.05, 200, 1000.0);
    EXPECT_GT(q200, studentized_range_quantile_upper(0.05, 100, 1000.0));
    EXPECT_THROW(studentized_range_cdf(1.0, 1, 10.0), std::domain_error);
    EXPECT_THROW(studentized_range_cdf(1.0, 201, 10.0), std::domain_error);
    EXPECT_THROW(studentized_range_cdf(1.0, 3, 0.5), std::domain_error);
    EXPECT_THROW(studentized_range_cdf(-1.0, 3, 10.0), std::domain_error);
    EXPECT_THROW(studentized_range_cdf(NAN, 3, 10.0), std::domain_error);
    EXPECT_THROW(studentized_range_quantile_upper(0.0, 3, 10.0), std::domain_error);
    EXPECT_THROW(studentized_range_quantile_upper(1.0, 3, 10.0), std::domain_error);
}

TEST(StudentizedRange, ManyGroupsAtTinyDfMatchIndependentQuadrature) {
    // The corners the grid does not reach: df = 1 with k = 200, df = 2 with k = 100
    // (typical, tail and far-tail q), against the extended-precision reference.
    struct Case {
        int k;
        double df, q;
    };
    std::vector<Case> cases = {{200, 1, 6}, {100, 2, 30}};
    if (long_tests())
        for (double q : {0.5, 3.0, 12.0, 60.0, 300.0}) {
            cases.push_back({200, 1, q});
            cases.push_back({100, 2, q});
        }
    for (const Case& c : cases) {
        const auto ref = test::reference_studentized_range(c.q, c.k, c.df);
        const double cdf = studentized_range_cdf(c.q, c.k, c.df);
        const double upper = studentized_range_upper(c.q, c.k, c.df);
        EXPECT_LT(std::fabs(cdf - static_cast<double>(ref.lower)), 1e-9)
            << "k=" << c.k << " df=" << c.df << " q=" << c.q;
        EXPECT_NEAR(upper / static_cast<double>(ref.upper), 1.0, 1e-7)
            << "k=" << c.k << " df=" << c.df << " q=" << c.q;
        if (ref.lower < 0.5L)
            EXPECT_NEAR(cdf / static_cast<double>(ref.lower), 1.0, 1e-7);
    }
}

// Arguments that cover small and large k, heavy (df = 1) and light tails, and both
// sides of the switch between summing the lower and the upper tail.
const int kIdentityK[] = {2, 3, 10, 50, 200};
const double kIdentityDf[] = {1, 2.5, 12, 300, 1e6, kInf};

TEST(StudentizedRange, TailsAddUpAndAreMonotone) {
    for (int k : kIdentityK)
        for (double df : kIdentityDf) {
            double previous_cdf = 0, previous_upper = 1;
            for (double e = -2; e <= 6; e += 0.01) {
                const double q = std::pow(10.0, e);
                const double cdf = studentized_range_cdf(q, k, df);
                const double upper = studentized_range_upper(q, k, df);
                ASSERT_TRUE(cdf >= 0 && cdf <= 1 && upper >= 0 && upper <= 1);
                EXPECT_NEAR(cdf + upper, 1.0, 2e-16) << "k=" << k << " df=" << df;
                EXPECT_GE(cdf, previous_cdf - 1e-15)
                    << "k=" << k << " df=" << df << " q=" << q;
                EXPECT_LE(upper, previous_upper * (1 + 1e-12) + 1e-300)
                    << "k=" << k << " df=" << df << " q=" << q;
                previous_cdf = cdf;
                previous_upper = upper;
            }
        }
}

TEST(StudentizedRange, DensityIntegratesToOneAndIsTheCdfSlope) {
    for (int k : kIdentityK)
        for (double df : kIdentityDf) {
            // Int_a^b f(q) dq over q = e^x (trapezoid: the integrand is smooth and decays
            // at both ends), plus the tails outside [a, b], is 1.
            // (At x = -20 the integrand is ~1e-9 and flat: no end correction needed.)
            const double a = std::exp(-20.0), b = std::exp(12.0), step = 0.01;
            double integral = 0;
            for (int i = 0; i <= 3200; ++i) {
                const double x = -20.0 + i * step, q = std::exp(x);
                const double weight = (i == 0 || i == 3200) ? 0.5 : 1.0;
                integral += weight * step * q * studentized_range_density(q, k, df);
            }
            const double total = integral + studentized_range_cdf(a, k, df) +
                                 studentized_range_upper(b, k, df);
            EXPECT_NEAR(total, 1.0, 1e-9) << "k=" << k << " df=" << df;
            // Central differences of the smaller tail (4th order), on a step short
            // against the tails' scales (W ~ q^(k-1), U ~ e^(-q^2/4)) but long enough
            // that rounding in the tails (1e-16 absolute) stays far below the change.
            for (double q : {0.3, 1.0, 3.0, 6.0, 15.0, 80.0}) {
                const double d = 1e-3 * q / (k + std::min(q * q, 100.0));
                const bool use_upper = studentized_range_upper(q, k, df) < 0.5;
                auto tail = [&](double x) {
                    return use_upper ? -studentized_range_upper(x, k, df)
                                     : studentized_range_cdf(x, k, df);
                };
                const double slope = (8 * (tail(q + d) - tail(q - d)) -
                                      (tail(q + 2 * d) - tail(q - 2 * d))) /
                                     (12 * d);
                const double density = studentized_range_density(q, k, df);
                if (density < 1e-280) continue;
                EXPECT_NEAR(slope / density, 1.0, 1e-6)
                    << "k=" << k << " df=" << df << " q=" << q;
            }
        }
}

TEST(StudentizedRange, ContinuousWhereDfBecomesInfinite) {
    for (int k : {2, 10, 200})
        for (double q : {0.5, 3.0, 5.0, 9.0}) {
            const double at_inf = studentized_range_cdf(q, k, kInf);
            EXPECT_NEAR(studentized_range_cdf(q, k, 1e11), at_inf, 1e-9) << k << " " << q;
            EXPECT_NEAR(studentized_range_cdf(q, k, 0.999999e12), at_inf, 1e-11);
            EXPECT_EQ(studentized_range_cdf(q, k, 1e12), at_inf);
            const double upper_inf = studentized_range_upper(q, k, kInf);
            EXPECT_NEAR(studentized_range_upper(q, k, 0.999999e12) / upper_inf, 1.0,
                        1e-9);
        }
}

TEST(StudentizedRange, QuantileRoundTripsToTwelveDigits) {
    for (int k : {2, 3, 10, 100, 200})
        for (double df : {1.0, 2.0, 5.0, 30.0, 1e3, kInf})
            for (double q0 : {0.2, 1.0, 3.5, 7.0, 25.0, 400.0}) {
                const double p = studentized_range_upper(q0, k, df);
                // (Near 1, p itself holds too few digits of 1 - p for 12 in q.)
                if (!(p > 1e-300 && p <= 0.999)) continue;
                const double q = studentized_range_quantile_upper(p, k, df);
                // Either q0 comes back to 12 digits, or the CDF is flat to rounding
                // (1e-14 in P) over the gap, and q reproduces p to 13 digits.
                const double p_again = studentized_range_upper(q, k, df);
                EXPECT_TRUE(std::fabs(q / q0 - 1.0) < 1e-12 ||
                            std::fabs(p_again / p - 1.0) < 1e-13)
                    << "k=" << k << " df=" << df << " q=" << q0 << ": " << q << ", p "
                    << p << " vs " << p_again;
            }
    // k = 2: the quantile is sqrt 2 times Student's t (or normal) quantile at p / 2.
    for (double df : {1.0, 2.0, 7.0, 100.0, kInf})
        for (double p : {0.9, 0.5, 0.05, 1e-3, 1e-8}) {
            const double expected =
                std::isinf(df)
                    ? 2.0 * boost::math::erfc_inv(p)
                    : std::sqrt(2.0) * boost::math::quantile(boost::math::complement(
                                           boost::math::students_t(df), 0.5 * p));
            EXPECT_NEAR(studentized_range_quantile_upper(p, 2, df) / expected, 1.0, 1e-12)
                << "df=" << df << " p=" << p;
        }
}

TEST(StudentizedRange, ThreadsBuildTablesOnceAndAgree) {
    // A k no other test uses, so the table is built while the threads race for it.
    const int k = 137;
    auto evaluate = [k] {
        std::vector<double> values;
        for (double df : {1.0, 7.0, 1e5, kInf})
            for (double q : {0.5, 4.0, 6.5, 40.0, 1e5}) {
                values.push_back(studentized_range_upper(q, k, df));
                values.push_back(studentized_range_cdf(q, k, df));
            }
        return values;
    };
    std::vector<std::vector<double>> results(4);
    std::vector<std::thread> threads;
    for (auto& result : results)
        threads.emplace_back([&result, &evaluate] { result = evaluate(); });
    for (auto& t : threads) t.join();
    const std::vector<double> single = evaluate();
    for (const auto& result : results) EXPECT_EQ(result, single);  // bit for bit
}

}  // namespace
}  // namespace lucent::analysis
