// QUEST against PsychoPy's own tests (psychopy/tests/test_data/test_StairHandlers.py;
// tests/study/adaptive/PSYCHOPY.md lists each value's source), and the hard cases:
// all-correct and all-wrong observers stay finite and inside the range.
#include "study/adaptive/quest.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace lucent::study::adaptive {
namespace {

// test_QuestHandler's settings.
QuestSettings psychopy_quest() {
    QuestSettings s;
    s.start = 50;
    s.start_sd = 50;
    s.p_threshold = 0.82;
    s.n_trials = 10;
    s.method = QuestMethod::quantile;
    s.beta = 3.5;
    s.gamma = 0.5;
    s.delta = 0.01;
    s.grain = 0.01;
    s.range = 100;
    s.min_value = 0;
    s.max_value = 100;
    return s;
}

// makeBasicResponseCycles(cycles=3, nCorrect=2, nIncorrect=2, length=10).
const std::vector<int> kResponses = {1, 1, 0, 0, 1, 1, 0, 0, 1, 1};

// PsychoPy's intensities, as its test prints them (17 significant digits).
const std::vector<double> kIntensities = {50,
                                          45.139710407074872,
                                          37.291086503930742,
                                          58.297413127139947,
                                          80.182967131096547,
                                          75.295251409003527,
                                          71.57627192423783,
                                          79.881680484036906,
                                          90.712313302815517,
                                          88.265808957695796};

void expect_relative(double actual, double expected, double tolerance, const char* what) {
    EXPECT_LE(std::fabs(actual - expected), tolerance * std::fabs(expected))
        << what << ": " << actual << " against PsychoPy's " << expected;
}

void run(AdaptiveProcedure& quest, const std::vector<int>& responses) {
    for (int r : responses) {
        ASSERT_FALSE(quest.finished());
        quest.next();
        quest.add_response(r == 1);
    }
}

TEST(Quest, PsychoPyQuantileTrackMeanModeAndQuantile) {
    Quest quest(psychopy_quest());
    run(quest, kResponses);
    EXPECT_TRUE(quest.finished());
    EXPECT_EQ(quest.responses(), kResponses);
    ASSERT_EQ(quest.intensities().size(), kIntensities.size());
    for (std::size_t i = 0; i < kIntensities.size(); ++i)
        expect_relative(quest.intensities()[i], kIntensities[i], 1e-12, "intensity");
    // The printed digits: mean 86.0772169427, mode 80.11, quantile 86.3849031085.
    EXPECT_NEAR(quest.mean(), 86.0772169427, 5e-11);
    EXPECT_NEAR(quest.mode(), 80.11, 1e-9);
    EXPECT_NEAR(quest.quantile(), 86.3849031085, 5e-11);
    EXPECT_EQ(quest.settings().start, 50);
    EXPECT_EQ(quest.settings().start_sd, 50);
    EXPECT_FALSE(quest.hit_range());
    EXPECT_THROW(quest.next(), std::logic_error);
}

// The grid checks of test_QuestHandler: (max - min) / grain + 1 points, grain apart,
// from -range/2 to range/2.
TEST(Quest, PsychoPyGridDimensions) {
    Quest quest(psychopy_quest());
    const auto& x = quest.grid();
    EXPECT_EQ(x.size(), 10001u);
    EXPECT_NEAR(x[1] - x[0], 0.01, 1e-12);
    EXPECT_EQ(x.front(), -50.0);
    EXPECT_EQ(x.back(), 50.0);
    // No range: 500 grains.
    QuestSettings s = psychopy_quest();
    s.range.reset();
    EXPECT_EQ(Quest(s).grid().size(), 501u);
}

// test_epsilon: Harvey (1986), Table 3: beta 3.5, gamma 0, delta 0 put the threshold
// 0.0571 log units (epsilon) below the point the Weibull reaches pThreshold.
TEST(Quest, PsychoPyEpsilonOfHarvey1986) {
    const double beta = 3.5, epsilon = 0.0571;
    const double p =
        1 - std::exp(-std::pow(10.0, beta * epsilon));  // the test's weibull()
    QuestSettings s;
    s.start = 0.5;
    s.start_sd = 1;
    s.p_threshold = p;
    s.beta = beta;
    s.gamma = 0;
    s.delta = 0;
    s.n_trials = 10;
    EXPECT_NEAR(Quest(s).epsilon(), epsilon, 1e-4);
}

// test_attributes: the settings are kept as given.
TEST(Quest, PsychoPyAttributes) {
    QuestSettings s;
    s.start = 0.5;
    s.start_sd = 0.2;
    s.p_threshold = 0.63;
    s.n_trials = 10;
    s.beta = 3.5;
    s.gamma = 0.01;
    s.delta = 0.02;
    s.grain = 0.01;
    s.range = 1;
    const Quest q(s);
    EXPECT_EQ(q.settings().beta, 3.5);
    EXPECT_EQ(q.settings().gamma, 0.01);
    EXPECT_EQ(q.settings().delta, 0.02);
    EXPECT_EQ(q.settings().grain, 0.01);
    EXPECT_EQ(*q.settings().range, 1);
    EXPECT_EQ(q.grid().size(), 101u);
}

// test_multiStairQuestSequentialIdenticalConditions: two identical QUESTs interleaved,
// each given the same answers, each gives PsychoPy's track.
TEST(Quest, PsychoPyInterleavedIdenticalQuests) {
    std::vector<std::unique_ptr<AdaptiveProcedure>> list;
    list.push_back(std::make_unique<Quest>(psychopy_quest()));
    list.push_back(std::make_unique<Quest>(psychopy_quest()));
    Interleaved stairs(std::move(list), 0, InterleaveOrder::sequential);
    std::vector<std::size_t> trial_of(2, 0);
    while (!stairs.finished()) {
        const auto t = stairs.next();
        stairs.add_response(kResponses[trial_of[t.procedure]++] == 1);
    }
    for (std::size_t i = 0; i < 2; ++i) {
        const auto& q = static_cast<const Quest&>(stairs.procedure(i));
        ASSERT_EQ(q.intensities().size(), kIntensities.size());
        for (std::size_t k = 0; k < kIntensities.size(); ++k)
            expect_relative(q.intensities()[k], kIntensities[k], 1e-12, "intensity");
        EXPECT_NEAR(q.mean(), 86.0772169427, 5e-11);
        EXPECT_NEAR(q.mode(), 80.11, 1e-9);
        EXPECT_NEAR(q.quantile(), 86.3849031085, 5e-11);
    }
}

// The 'mean' and 'mode' methods propose the posterior's mean and mode.
TEST(Quest, MeanAndModeMethodsProposeThoseStatistics) {
    for (QuestMethod method : {QuestMethod::mean, QuestMethod::mode}) {
        QuestSettings s = psychopy_quest();
        s.method = method;
        Quest quest(s);
        for (int r : kResponses) {
            quest.next();
            quest.add_response(r == 1);
            if (quest.finished()) break;
            const double expected =
                method == QuestMethod::mean ? quest.mean() : quest.mode();
            EXPECT_EQ(quest.upcoming().intensity, std::clamp(expected, 0.0, 100.0));
        }
    }
}

// The posterior's order statistics agree with each other.
TEST(Quest, StatisticsAreConsistent) {
    Quest quest(psychopy_quest());
    run(quest, kResponses);
    const auto [lo, hi] = quest.conf_interval();
    EXPECT_LT(lo, quest.quantile(0.5));
    EXPECT_LT(quest.quantile(0.5), hi);
    EXPECT_NEAR(quest.conf_interval_width(), hi - lo, 1e-12);
    EXPECT_GT(quest.sd(), 0);
    EXPECT_LT(quest.sd(), 50);
    // A Gaussian prior alone: mean = mode = median = start, sd = startValSd.
    QuestSettings s = psychopy_quest();
    s.range = 1000;
    s.grain = 0.1;
    const Quest prior(s);
    EXPECT_NEAR(prior.mean(), 50, 1e-9);
    EXPECT_NEAR(prior.mode(), 50, 1e-9);
    EXPECT_NEAR(prior.quantile(0.5), 50, 0.1);  // within a grain
    EXPECT_NEAR(prior.sd(), 50, 1e-6);
    // QUEST's most informative order for this Weibull (Pelli 1987).
    EXPECT_GT(prior.quantile_order(), 0.5);
    EXPECT_LT(prior.quantile_order(), 1);
    EXPECT_THROW(prior.quantile(1.5), std::invalid_argument);
}

// stopInterval: finished once the 5-95 % interval is narrower than asked.
TEST(Quest, StopsWhenTheIntervalIsNarrowEnough) {
    QuestSettings s = psychopy_quest();
    s.n_trials.reset();
    s.stop_interval = 40;
    Quest quest(s);
    int n = 0;
    while (!quest.finished() && n < 500) {
        const double x = quest.next().intensity;
        quest.add_response(x > 60 ? (n % 10 != 0) : (n % 3 == 0));
        ++n;
    }
    EXPECT_TRUE(quest.finished());
    EXPECT_LT(quest.conf_interval_width(), 40);
    EXPECT_LT(n, 500);
}

// An observer always right or always wrong: QUEST walks to the end of its table and
// stays there, finite and inside [minVal, maxVal]; with a range narrower than the
// table it is held at the bound and says so. No NaN anywhere.
TEST(Quest, AllCorrectOrAllWrongStaysFiniteAndInRange) {
    for (bool narrow : {false, true}) {
        for (bool answer : {true, false}) {
            QuestSettings s = psychopy_quest();
            s.n_trials = 400;
            if (narrow) {
                s.min_value = 20;
                s.max_value = 80;
            }
            const double lo = *s.min_value, hi = *s.max_value;
            Quest quest(s);
            for (int i = 0; i < 400; ++i) {
                const Proposal p = quest.next();
                ASSERT_TRUE(std::isfinite(p.intensity)) << "trial " << i;
                EXPECT_GE(p.intensity, lo);
                EXPECT_LE(p.intensity, hi);
                quest.add_response(answer);
            }
            EXPECT_TRUE(quest.finished());
            const double last = quest.intensities().back();
            if (narrow) {
                EXPECT_TRUE(quest.hit_range()) << (answer ? "all correct" : "all wrong");
                EXPECT_TRUE(quest.clamped_trials().back());
                EXPECT_EQ(last, answer ? lo : hi);
            } else {
                EXPECT_FALSE(quest.hit_range());
                EXPECT_NEAR(last, answer ? lo : hi, 1.0);
            }
            for (double v : {quest.mean(), quest.mode(), quest.quantile(), quest.sd(),
                             quest.conf_interval_width()})
                EXPECT_TRUE(std::isfinite(v));
            double total = 0;
            for (double p : quest.posterior()) total += p;
            EXPECT_TRUE(std::isfinite(total));
            EXPECT_GT(total, 0);
        }
    }
}

// With no lapse (delta 0) and no guessing, contradictory answers far from the prior
// cannot empty the posterior.
TEST(Quest, NoLapseContradictionsKeepAPosterior) {
    QuestSettings s;
    s.start = 0;
    s.start_sd = 0.5;
    s.p_threshold = 0.63;
    s.gamma = 0;
    s.delta = 0;
    s.range = 5;
    s.n_trials = 40;
    Quest quest(s);
    for (int i = 0; i < 40; ++i) {
        quest.next();
        quest.add_response(i % 2 == 0, i % 2 == 0 ? -2.4 : 2.4);
    }
    EXPECT_TRUE(std::isfinite(quest.mean()));
    EXPECT_TRUE(std::isfinite(quest.quantile()));
    EXPECT_TRUE(std::isfinite(quest.sd()));
}

// An intensity far off the table (PsychoPy: "Pdf will be inexact") is read at its end.
TEST(Quest, IntensityOffTheTableIsTakenAtItsEnd) {
    Quest quest(psychopy_quest());
    quest.next();
    quest.add_response(true, 1e12);
    quest.next();
    quest.add_response(false, -1e12);
    EXPECT_TRUE(std::isfinite(quest.mean()));
    EXPECT_EQ(quest.intensities(), (std::vector<double>{1e12, -1e12}));
}

TEST(Quest, RefusesBadSettingsNamingTheParameter) {
    auto message = [](QuestSettings s) {
        try {
            Quest quest(std::move(s));
        } catch (const std::invalid_argument& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            return what;
        }
        return std::string("(accepted)");
    };
    auto contains = [](const std::string& s, const char* word) {
        return s.find(word) != std::string::npos;
    };
    QuestSettings s = psychopy_quest();
    s.start_sd = 0;
    EXPECT_TRUE(contains(message(s), "startValSd"));
    s = psychopy_quest();
    s.grain = -1;
    EXPECT_TRUE(contains(message(s), "grain"));
    s = psychopy_quest();
    s.range = 0;
    EXPECT_TRUE(contains(message(s), "range"));
    s = psychopy_quest();
    s.gamma = 0.9;
    EXPECT_TRUE(contains(message(s), "gamma"));
    s = psychopy_quest();
    s.p_threshold = 1;
    EXPECT_TRUE(contains(message(s), "pThreshold"));
    s = psychopy_quest();
    s.n_trials.reset();
    EXPECT_TRUE(contains(message(s), "nTrials"));
    s = psychopy_quest();
    s.start = 150;
    EXPECT_TRUE(contains(message(s), "outside"));
    s = psychopy_quest();
    s.range = 0.02;  // a 3-point table cannot reach pThreshold 0.99
    s.p_threshold = 0.99;
    EXPECT_TRUE(contains(message(s), "pThreshold"));
    EXPECT_THROW(parse_quest_method("median"), std::invalid_argument);
    EXPECT_EQ(parse_quest_method("mode"), QuestMethod::mode);
}

}  // namespace
}  // namespace lucent::study::adaptive
