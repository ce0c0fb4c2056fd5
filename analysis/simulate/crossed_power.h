#pragma once
// Power of a rating study in which both participants and stimuli are sampled (Westfall,
// Kenny and Judd 2014): how many pictures per level a study needs, not only how many
// people. Every participant rates every stimulus; each level has its own stimuli.
//
//   rating = mean_level + p_participant + s_stimulus + e,
//   p ~ N(0, participant_sd^2), s ~ N(0, stimulus_sd^2), e ~ N(0, residual_sd^2),
//
// rounded and clamped to 1..7 for the ordinal model (clmm) or with `likert`. Each
// simulated study is analysed by the mixed model (lmm: Satterthwaite's F of the level;
// clmm: the likelihood ratio) and, for comparison, by the repeated-measures ANOVA of each
// participant's mean per level, which ignores the stimulus variance and so rejects a true
// null more often than alpha says (Judd, Westfall and Kenny 2012).
//
// Closed form (lmm, continuous responses): with balanced data the test is the F test of
// the stimulus means, F(k - 1, k (m - 1)) with noncentrality
// lambda = m sum (mean_j - grand)^2 / (stimulus_sd^2 + residual_sd^2 / n).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/mixed/rating_models.h"
#include "analysis/simulate/power.h"

namespace lucent::analysis {

struct CrossedPowerSpec {
    std::string model = "lmm";  // a registered model with a power simulation
    int participants = 30;
    int stimuli_per_level = 6;
    std::vector<double> level_means;
    double participant_sd = 0.5, stimulus_sd = 0.5, residual_sd = 1.0;
    double alpha = 0.05;
    int simulations = 200;
    std::uint64_t seed = 1;
    bool likert = false;  // always for a model that rounds to the scale (clmm)
};

// One simulated study in model form: responses, level of each, participant and stimulus
// codes. A model's power simulation (RatingModelSpec::crossed_p) tests its level.
struct CrossedSample {
    std::vector<double> y;
    mixed::FactorColumn level, participant, stimulus;
};
// The level's treatment-coded columns, after an intercept column when `intercept`.
mixed::FixedDesign crossed_level_design(const CrossedSample& study, bool intercept);

struct CrossedPowerResult {
    CrossedPowerSpec spec;
    PowerEstimate model_test;      // the mixed model's test of the level
    PowerEstimate by_participant;  // RM ANOVA on participants' means (stimuli ignored)
    std::optional<double> closed_form;  // lmm with continuous responses
    int failed_fits = 0;  // fits that gave no p-value (counted as not rejecting)
};

// Throws InputError naming the option (--participants, --stimuli, ...) when the spec
// cannot describe a study.
void check_crossed_power_spec(const CrossedPowerSpec& spec);
std::optional<double> crossed_closed_form_power(const CrossedPowerSpec& spec);
// `progress` (may be empty) is called after each simulated study with (done, total).
CrossedPowerResult estimate_crossed_power(
    const CrossedPowerSpec& spec,
    const std::function<void(int done, int total)>& progress = {});

}  // namespace lucent::analysis
