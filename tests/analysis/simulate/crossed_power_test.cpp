// Power of designs with participants and stimuli both sampled (Westfall, Kenny and Judd
// 2014): the closed form against the noncentral t it reduces to for two levels, the
// simulated linear mixed model against the closed form, and the type I error of the
// mixed model against that of the repeated-measures ANOVA of participant means, which
// ignores the stimuli (Judd, Westfall and Kenny 2012).
#include "analysis/simulate/crossed_power.h"

#include <gtest/gtest.h>

#include <boost/math/distributions/non_central_t.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>

namespace lucent::analysis {
namespace {

CrossedPowerSpec two_levels(int participants, int stimuli, double difference) {
    CrossedPowerSpec spec;
    spec.participants = participants;
    spec.stimuli_per_level = stimuli;
    spec.level_means = {4.0, 4.0 + difference};
    spec.participant_sd = 0.7;
    spec.stimulus_sd = 0.4;
    spec.residual_sd = 1.2;
    spec.alpha = 0.05;
    return spec;
}

// Two levels: the level difference of stimulus means over its standard error is a
// noncentral t with 2 (m - 1) df and noncentrality d / sqrt(2 (s^2 + e^2 / n) / m).
TEST(CrossedPower, ClosedFormIsTheNoncentralTForTwoLevels) {
    for (int m : {2, 4, 8, 20}) {
        const CrossedPowerSpec spec = two_levels(20, m, 0.5);
        const double df = 2.0 * (m - 1);
        const double se = std::sqrt(2.0 * (0.4 * 0.4 + 1.2 * 1.2 / 20) / m);
        const double critical =
            boost::math::quantile(boost::math::students_t(df), 1.0 - spec.alpha / 2);
        const boost::math::non_central_t t(df, 0.5 / se);
        const double expected = boost::math::cdf(boost::math::complement(t, critical)) +
                                boost::math::cdf(t, -critical);
        ASSERT_TRUE(crossed_closed_form_power(spec).has_value());
        EXPECT_NEAR(*crossed_closed_form_power(spec), expected, 1e-9) << m;
    }
    EXPECT_FALSE(crossed_closed_form_power([] {
                     auto spec = two_levels(20, 4, 0.5);
                     spec.model = "clmm";
                     return spec;
                 }())
                     .has_value());
}

// With six pictures per level the variance estimates stay away from zero, where the
// mixed model's Satterthwaite F is the balanced F test: simulation meets closed form.
TEST(CrossedPower, SimulatedMixedModelMeetsTheClosedForm) {
    CrossedPowerSpec spec = two_levels(16, 6, 0.6);
    spec.simulations = 300;
    spec.seed = 7;
    const CrossedPowerResult result = estimate_crossed_power(spec);
    ASSERT_TRUE(result.closed_form.has_value());
    EXPECT_EQ(result.failed_fits, 0);
    EXPECT_NEAR(result.model_test.power, *result.closed_form,
                4.0 * std::max(result.model_test.mc_error, 0.01))
        << "closed form " << *result.closed_form;
}

// Equal means: the mixed model rejects at about alpha; the RM ANOVA of participant means
// treats the pictures' own differences as the levels' and rejects far more often.
TEST(CrossedPower, IgnoringStimuliInflatesTypeOneErrorAndTheMixedModelDoesNot) {
    CrossedPowerSpec spec = two_levels(30, 4, 0.0);
    spec.stimulus_sd = 0.5;
    spec.residual_sd = 1.0;
    spec.simulations = 400;
    spec.seed = 11;
    const CrossedPowerResult result = estimate_crossed_power(spec);
    EXPECT_NEAR(result.model_test.power, spec.alpha, 4.0 * std::sqrt(0.05 * 0.95 / 400));
    EXPECT_GT(result.by_participant.power, 0.3);
}

// The ordinal model on 1..7 ratings: a large effect is found nearly always; every fit
// gives a p-value.
TEST(CrossedPower, OrdinalModelPowerOnASmallDesign) {
    CrossedPowerSpec spec = two_levels(8, 3, 2.5);
    spec.model = "clmm";
    spec.stimulus_sd = 0.3;
    spec.simulations = 30;
    const CrossedPowerResult result = estimate_crossed_power(spec);
    EXPECT_EQ(result.failed_fits, 0);
    EXPECT_GT(result.model_test.power, 0.8);
    EXPECT_FALSE(result.closed_form.has_value());
}

TEST(CrossedPower, BadSpecsNameTheOption) {
    auto message = [](CrossedPowerSpec spec) {
        try {
            check_crossed_power_spec(spec);
        } catch (const InputError& error) {
            return std::string(error.what());
        }
        return std::string("accepted");
    };
    CrossedPowerSpec spec = two_levels(20, 1, 0.5);
    EXPECT_EQ(message(spec).rfind("--stimuli must lie in [2, 1000]", 0), 0u);
    spec = two_levels(20, 4, 0.5);
    spec.stimulus_sd = -1;
    EXPECT_EQ(message(spec).rfind("--stimulus-sd", 0), 0u);
    spec = two_levels(1, 4, 0.5);
    EXPECT_EQ(message(spec).rfind("--participants", 0), 0u);
    spec = two_levels(2000, 1000, 0.5);
    EXPECT_NE(message(spec).find("ratings per simulated study"), std::string::npos);
    spec = two_levels(20, 4, 0.5);
    spec.model = "anova";
    EXPECT_EQ(message(spec).rfind("--model", 0), 0u);
}

}  // namespace
}  // namespace lucent::analysis
