// Issue 31's engines together without a display: a simulated observer with a known
// psychometric function answers a 1-up/3-down staircase and a QUEST run on the
// difference from a standard; the psychometric fit of the trials recovers the observer's
// threshold and spread. The truth is the observer model's parameters, never a fit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/psychometric/psychometric.h"
#include "study/adaptive/quest.h"
#include "study/adaptive/staircase.h"
#include "study/simulated_observer.h"

namespace lucent::study {
namespace {

// Trials of `participants` runs of `make()`'s procedure by `observer` (2AFC).
std::vector<analysis::PsychometricTrial> run(
    const DetectionObserver& observer, int participants,
    const std::function<std::unique_ptr<adaptive::AdaptiveProcedure>()>& make) {
    std::mt19937_64 rng(31);
    std::vector<analysis::PsychometricTrial> trials;
    for (int p = 0; p < participants; ++p) {
        std::unique_ptr<adaptive::AdaptiveProcedure> procedure = make();
        while (!procedure->finished()) {
            const double delta = procedure->next().intensity;
            const bool correct = simulated_detection(observer, delta, 0.5, rng);
            procedure->add_response(correct);
            trials.push_back({delta, correct});
        }
    }
    return trials;
}

TEST(ThresholdRecovery, AStaircaseAndQuestRecoverTheObserversThreshold) {
    const DetectionObserver observer = DetectionObserver::parse("2,0.6,0.02");
    analysis::PsychometricOptions options;
    options.guess = 0.5;
    options.bootstrap = 200;
    options.seed = 4;

    // 1-up/3-down converges near 79.4% correct; 8 runs of 80 trials.
    const auto staircase = run(observer, 8, [] {
        adaptive::StaircaseSettings s;
        s.start = 5;
        s.n_up = 1;
        s.n_down = 3;
        s.step_sizes = {1.0, 0.5, 0.25};
        s.step_type = adaptive::StepType::lin;
        s.min_value = 0;
        s.n_trials = 80;
        return std::make_unique<adaptive::Staircase>(s);
    });
    const analysis::PsychometricFit fit = analysis::fit_psychometric(staircase, options);
    ASSERT_EQ(fit.threshold.status, analysis::ThresholdStatus::estimated);
    ASSERT_TRUE(fit.threshold.value && fit.threshold.ci_low && fit.threshold.ci_high);
    EXPECT_NEAR(*fit.threshold.value, observer.threshold, 0.3);
    EXPECT_LE(*fit.threshold.ci_low, observer.threshold);
    EXPECT_GE(*fit.threshold.ci_high, observer.threshold);
    ASSERT_TRUE(fit.beta.has_value());
    EXPECT_NEAR(*fit.beta, observer.spread, 0.35);

    // QUEST places its trials near its threshold estimate: 8 runs of 60.
    const auto quest = run(observer, 8, [] {
        adaptive::QuestSettings q;
        q.start = 3;
        q.start_sd = 3;
        q.p_threshold = 0.82;
        q.n_trials = 60;
        q.min_value = 0;
        q.max_value = 10;
        q.grain = 0.01;
        q.range = 20;
        return std::make_unique<adaptive::Quest>(q);
    });
    const analysis::PsychometricFit quest_fit =
        analysis::fit_psychometric(quest, options);
    ASSERT_EQ(quest_fit.threshold.status, analysis::ThresholdStatus::estimated);
    EXPECT_NEAR(*quest_fit.threshold.value, observer.threshold, 0.3);
    EXPECT_LE(*quest_fit.threshold.ci_low, observer.threshold);
    EXPECT_GE(*quest_fit.threshold.ci_high, observer.threshold);
}

}  // namespace
}  // namespace lucent::study
