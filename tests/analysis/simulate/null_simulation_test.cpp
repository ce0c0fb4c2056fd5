// Under no effect, the classical ANOVA must reject at alpha = .05 in 5% +- 1% of 2,000
// simulated studies, and Tukey's HSD must declare any pair different in at most 6%.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "analysis/data/grouping.h"
#include "analysis/simulate/simulate.h"
#include "analysis/stats/tukey.h"

namespace lucent::analysis {
namespace {

TEST(Simulation, SameSeedSameStudy) {
    SimulationSpec spec;
    spec.seed = 42;
    const LongTable a = simulate_study(spec), b = simulate_study(spec);
    ASSERT_EQ(a.rows.size(), 38u * 3);
    for (std::size_t i = 0; i < a.rows.size(); ++i)
        ASSERT_EQ(*a.rows[i].rating, *b.rows[i].rating);
    spec.seed = 43;
    const LongTable c = simulate_study(spec);
    int differing = 0;
    for (std::size_t i = 0; i < a.rows.size(); ++i)
        differing += *a.rows[i].rating != *c.rows[i].rating;
    EXPECT_GT(differing, 10);
    for (const RatingRow& row : a.rows) ASSERT_TRUE(*row.rating >= 1 && *row.rating <= 7);
}

// A stimulus's own offset is shared by every participant who rates it: with no noise
// and no participant spread, each stimulus gets one rating from everyone, and the
// stimuli of a level differ.
TEST(Simulation, StimulusSpreadIsSharedAcrossParticipants) {
    SimulationSpec spec;
    spec.participants = 5;
    spec.stimuli_per_level = 8;
    spec.noise_sd = 0.0;
    spec.stimulus_sd = 1.5;
    spec.seed = 3;
    const LongTable table = simulate_study(spec);
    std::map<std::string, std::set<double>> ratings_of;
    for (const RatingRow& row : table.rows)
        ratings_of[row.stimulus.str()].insert(*row.rating);
    std::set<double> distinct;
    for (const auto& [stimulus, ratings] : ratings_of) {
        EXPECT_EQ(ratings.size(), 1u) << stimulus;
        distinct.insert(*ratings.begin());
    }
    EXPECT_GE(distinct.size(), 3u);
}

struct NullRates {
    double anova = 0, tukey_any_pair = 0;
};

NullRates null_rejection_rates(int studies, const SimulationSpec& base) {
    int anova_rejections = 0, familywise_errors = 0;
    for (int s = 0; s < studies; ++s) {
        SimulationSpec spec = base;
        spec.seed = 1000 + s;
        const auto pairs = split_by_question_and_factor(simulate_study(spec));
        const AnovaResult anova = one_way_anova(pairs[0].data);
        anova_rejections += anova.p && *anova.p < 0.05;
        // Intervals only (a pair is significant iff its interval excludes 0).
        const TukeyResult tukey = tukey_hsd(pairs[0].data, anova, {0.05, false});
        bool any = false;
        for (const TukeyPair& p : tukey.pairs) any |= *p.lower > 0 || *p.upper < 0;
        familywise_errors += any;
    }
    return {double(anova_rejections) / studies, double(familywise_errors) / studies};
}

TEST(Simulation, NullStudiesRejectAtTheNominalRate) {
    SimulationSpec spec;
    spec.participants = 20;
    spec.level_effects = {0.0, 0.0, 0.0, 0.0};
    spec.noise_sd = 1.5;  // spreads ratings over the 7 points
    const NullRates rates = null_rejection_rates(2000, spec);
    std::printf("[ NULL     ] ANOVA rejects %.2f%%, Tukey familywise error %.2f%%\n",
                100 * rates.anova, 100 * rates.tukey_any_pair);
    EXPECT_NEAR(rates.anova, 0.05, 0.01);
    EXPECT_LE(rates.tukey_any_pair, 0.06);
    EXPECT_GE(rates.tukey_any_pair, 0.03);  // not vacuously conservative
}

TEST(Simulation, RealEffectsAreDetected) {
    SimulationSpec spec;
    spec.participants = 20;
    spec.level_effects = {0.0, 0.0, 1.2};
    const NullRates rates = null_rejection_rates(200, spec);
    EXPECT_GT(rates.anova, 0.9);
    EXPECT_GT(rates.tukey_any_pair, 0.9);
}

}  // namespace
}  // namespace lucent::analysis
