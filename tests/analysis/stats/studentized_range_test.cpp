// The studentized range distribution against an independent extended-precision
// quadrature (studentized_range_reference.h), the closed form for k = 2 through Student's
// t, published table values, and the quantile's round trip.
#include "stats/studentized_range.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "stats/studentized_range_reference.h"

namespace lucent::analysis {
namespace {

constexpr double kInf = kInfiniteDf;

// k = 2: Q = sqrt(2) |T| with T ~ t(df), so P(Q > q) = 2 P(T > q / sqrt 2).
double upper_k2(double q, double df) {
    if (std::isinf(df)) return std::erfc(0.5 * q);
    return 2.0 * boost::math::cdf(boost::math::complement(boost::math::students_t(df),
                                                          q / std::sqrt(2.0)));
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
    const bool full = std::getenv("LUCENT_FULL_GRID") != nullptr;
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

}  // namespace
}  // namespace lucent::analysis
