// Power by simulation against the noncentral F (Boost's non_central_f, an independent
// path): a balanced between-subject one-way ANOVA, and the repeated-measures ANOVA under
// the compound symmetry of the simulation model; the null case gives alpha; the
// smallest sample agrees with the closed form's.
#include "analysis/simulate/power.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/non_central_f.hpp>
#include <cmath>

namespace lucent::analysis {
namespace {

// Power of the F test by the textbook formula, written out independently of power.cpp.
double noncentral_f_power(double df1, double df2, double lambda, double alpha) {
    const double critical = boost::math::quantile(
        boost::math::complement(boost::math::fisher_f(df1, df2), alpha));
    return 1.0 - boost::math::cdf(boost::math::non_central_f(df1, df2, lambda), critical);
}

TEST(Power, BetweenSubjectAnovaMatchesTheNoncentralF) {
    PowerSpec spec;
    spec.design = Design::Between;
    spec.participants = 10;  // per level
    spec.level_means = {0.0, 0.5, 1.0};
    spec.participant_sd = 0.6;
    spec.residual_sd = 0.8;  // total sd 1
    spec.alpha = 0.05;
    spec.simulations = 4000;
    const PowerResult r = estimate_power(spec);
    // lambda = n sum (m - grand)^2 / sigma^2 = 10 * 0.5 / 1.
    const double expected = noncentral_f_power(2, 27, 5.0, 0.05);
    ASSERT_TRUE(r.closed_form);
    EXPECT_NEAR(*r.closed_form, expected, 1e-9);
    EXPECT_NEAR(expected, 0.4579922755,
                1e-9);  // R: 1 - pf(qf(.95, 2, 27), 2, 27, ncp = 5)
    EXPECT_NEAR(r.one_way_anova.power, expected, 4 * r.one_way_anova.mc_error)
        << "closed form " << expected;
    EXPECT_FALSE(r.rm_anova.has_value());
    EXPECT_EQ(r.pairs.size(), 3u);
    EXPECT_EQ(r.pairwise_test, "Tukey HSD");
    // The extreme pair differs most: its power is the largest.
    EXPECT_GT(r.pairs[1].estimate.power, r.pairs[0].estimate.power);
    EXPECT_LE(r.any_pair.power, 1.0);
}

TEST(Power, WithinSubjectRmAnovaMatchesTheNoncentralFAndBeatsTheOneWayAnova) {
    PowerSpec spec;
    spec.design = Design::Within;
    spec.participants = 12;
    spec.level_means = {3.0, 3.4, 3.8, 3.5};
    spec.participant_sd = 1.0;  // large participant offsets: the pairing matters
    spec.residual_sd = 0.9;
    spec.alpha = 0.10;
    spec.simulations = 4000;
    const PowerResult r = estimate_power(spec);
    double grand = (3.0 + 3.4 + 3.8 + 3.5) / 4, spread = 0;
    for (double m : spec.level_means) spread += (m - grand) * (m - grand);
    const double expected = noncentral_f_power(3, 33, 12 * spread / (0.9 * 0.9), 0.10);
    ASSERT_TRUE(r.rm_anova && r.rm_anova_gg);
    EXPECT_NEAR(r.rm_anova->power, expected, 4 * r.rm_anova->mc_error) << expected;
    // The correction can only lose power; ignoring the pairing loses more here.
    EXPECT_LE(r.rm_anova_gg->power, r.rm_anova->power);
    EXPECT_LT(r.one_way_anova.power, r.rm_anova->power - 4 * r.rm_anova->mc_error);
    EXPECT_EQ(&r.primary(), &*r.rm_anova);
}

TEST(Power, EqualMeansRejectAtAlphaAndTheSeedFixesTheResult) {
    PowerSpec spec;
    spec.design = Design::Within;
    spec.participants = 8;
    spec.level_means = {4, 4, 4};
    spec.participant_sd = 0.5;
    spec.alpha = 0.10;
    spec.simulations = 4000;
    const PowerResult r = estimate_power(spec);
    EXPECT_NEAR(r.rm_anova->power, 0.10, 4 * std::sqrt(0.1 * 0.9 / 4000));
    EXPECT_NEAR(r.one_way_anova.power, 0.10,
                0.04);  // conservative with offsets, not liberal
    EXPECT_LE(r.any_pair.power,
              0.10 + 4 * std::sqrt(0.1 * 0.9 / 4000));  // Holm: FWER <= alpha
    EXPECT_DOUBLE_EQ(estimate_power(spec).rm_anova->power, r.rm_anova->power);
    spec.seed = 2;
    EXPECT_NE(estimate_power(spec).rm_anova->power, r.rm_anova->power);
}

TEST(Power, SmallestSampleAgreesWithTheClosedForm) {
    PowerSpec spec;
    spec.design = Design::Between;
    spec.level_means = {0.0, 0.4, 0.8};
    spec.residual_sd = 1.0;
    spec.alpha = 0.05;
    spec.simulations = 2000;
    // The closed form's smallest n per level reaching 0.8, by scanning n.
    int closed_n = 2;
    while (noncentral_f_power(2, 3.0 * (closed_n - 1), closed_n * 0.32, 0.05) < 0.8)
        ++closed_n;
    const SampleSize size = smallest_sample(spec, 0.8, 200);
    ASSERT_TRUE(size.participants);
    EXPECT_NEAR(*size.participants, closed_n, 2) << "closed form " << closed_n;
    EXPECT_GE(size.at.primary().power, 0.8);
    EXPECT_LE(size.evaluations, 10);  // bisection, not a scan

    const SampleSize unreachable = smallest_sample(spec, 0.8, 5);
    EXPECT_FALSE(unreachable.participants);
    EXPECT_LT(unreachable.at.primary().power, 0.8);
}

TEST(Power, LikertResponsesHaveNoClosedFormButStaySane) {
    PowerSpec spec;
    spec.participants = 20;
    spec.level_means = {3.0, 4.0, 5.0};
    spec.likert = true;
    spec.simulations = 200;
    const PowerResult r = estimate_power(spec);
    EXPECT_FALSE(r.closed_form);
    EXPECT_GT(r.rm_anova->power, 0.9);
}

TEST(Power, BadSpecsNameTheField) {
    PowerSpec spec;
    spec.level_means = {1, 2};
    spec.participants = 1;
    EXPECT_THROW(check_power_spec(spec), InputError);
    try {
        check_power_spec(spec);
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--participants"), std::string::npos);
    }
    spec.participants = 10;
    spec.level_means = {1};
    EXPECT_THROW(check_power_spec(spec), InputError);
    spec.level_means = {1, 2};
    spec.residual_sd = 0;
    EXPECT_THROW(check_power_spec(spec), InputError);
    spec.residual_sd = 1;
    spec.alpha = 1.5;
    EXPECT_THROW(check_power_spec(spec), InputError);
    spec.alpha = 0.05;
    EXPECT_NO_THROW(check_power_spec(spec));
    EXPECT_THROW(smallest_sample(spec, 1.2, 100), InputError);
}

}  // namespace
}  // namespace lucent::analysis
