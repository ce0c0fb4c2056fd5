// The simulated observer answers as its model says: the choice frequencies against the
// normal distribution's closed form, the scale's ends, and its one-line parse errors.
#include "study/simulated_observer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/study/study_fixtures.h"

namespace lucent::study {
namespace {

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// Share of answers 1 over n draws.
double share_of_first(const ObserverModel& m, const ChoiceStimuli& t, int n) {
    std::mt19937_64 rng(17);
    int first = 0;
    for (int i = 0; i < n; ++i) first += simulated_choice(m, t, rng) == 1 ? 1 : 0;
    return static_cast<double>(first) / n;
}

TEST(SimulatedObserver, PairsAreThurstoneCaseVOnTheModelsScale) {
    const ObserverModel m = ObserverModel::parse("0.5,0.2");
    // Values 25 and 4 on a series 0..100: psi = 0.5 and 0.2.
    const ChoiceStimuli t{Task::pair, {25, 4}, 0, 100};
    EXPECT_DOUBLE_EQ(m.scale(25, 0, 100), 0.5);
    EXPECT_DOUBLE_EQ(m.scale(4, 0, 100), 0.2);
    // P(first) = Phi((0.5 - 0.2) / (0.2 sqrt 2)) = Phi(1.0607) = 0.8556; 40000 draws
    // have a standard error of 0.0018.
    EXPECT_NEAR(share_of_first(m, t, 40000), normal_cdf(0.3 / (0.2 * std::sqrt(2.0))),
                0.008);
}

TEST(SimulatedObserver, TriadsAndQuadruplesCompareTheTwoDifferences) {
    const ObserverModel m = ObserverModel::parse("1,0.1");
    // Linear scale: the first pair differs by 0.3, the second by 0.1.
    const ChoiceStimuli triad{Task::triad, {0, 30, 40}, 0, 100};
    EXPECT_NEAR(share_of_first(m, triad, 40000), normal_cdf(0.2 / 0.1), 0.008);
    const ChoiceStimuli quad{Task::quadruple, {60, 65, 0, 40}, 0, 100};
    EXPECT_NEAR(share_of_first(m, quad, 40000), normal_cdf((0.05 - 0.4) / 0.1), 0.008);
}

TEST(SimulatedObserver, WithoutASeriesOrWithFullLapsesItFlipsACoin) {
    const ObserverModel m = ObserverModel::parse("1,0.01,1");
    const ChoiceStimuli t{Task::pair, {100, 0}, 0, 100};
    EXPECT_NEAR(share_of_first(m, t, 40000), 0.5, 0.008);
    const ChoiceStimuli unknown{Task::pair, {}, 0, 1};
    EXPECT_NEAR(share_of_first(ObserverModel{}, unknown, 40000), 0.5, 0.008);
}

TEST(SimulatedObserver, ReadsTheBlocksSeriesFromTheProtocol) {
    const Protocol p = lucent::test::choice_protocol();
    const ChoiceStimuli t = choice_stimuli(p, "mlds", {"s5", "s3", "s1"});
    EXPECT_EQ(t.task, Task::triad);
    EXPECT_EQ(t.values, (std::vector<double>{30, 20, 10}));
    EXPECT_EQ(t.lo, 10);
    EXPECT_EQ(t.hi, 30);
    // The pair block's obvious catch puts "more" at the low end (s1, r 10, over s5).
    EXPECT_TRUE(choice_stimuli(p, "pairs", {"s1", "s2"}).more_is_lower);
    EXPECT_FALSE(t.more_is_lower);
    const ChoiceStimuli lower{Task::pair, {25, 4}, 0, 100, true};
    EXPECT_NEAR(share_of_first(ObserverModel::parse("0.5,0.2"), lower, 40000),
                normal_cdf(-0.3 / (0.2 * std::sqrt(2.0))), 0.008);
    // The rating block names no series: no values.
    EXPECT_TRUE(choice_stimuli(p, "ratings", {"s1", "s3"}).values.empty());
}

TEST(SimulatedObserver, ABadModelIsOneLineNamingThePart) {
    for (const char* bad : {"0.5", "x,0.1", "0.5,0.1,2", "0,0.1", "0.5,-1", "1,2,3,4"}) {
        try {
            ObserverModel::parse(bad);
            ADD_FAILURE() << bad;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
        }
    }
}

// Issue 31's observers: the detection frequencies against their closed form (a
// cumulative Gaussian seen-probability mixed with the guess rate), and the match bias.
TEST(SimulatedObserver, DetectionFollowsItsPsychometricFunction) {
    const DetectionObserver o = DetectionObserver::parse("2,0.5,0.04");
    for (const double delta : {0.5, 2.0, 3.0, -3.0})
        for (const double guess : {0.5, 1.0 / 3.0}) {
            std::mt19937_64 rng(5);
            int correct = 0;
            for (int i = 0; i < 40000; ++i)
                correct += simulated_detection(o, delta, guess, rng) ? 1 : 0;
            // Closed form: (1 - lapse)(seen + (1 - seen) guess) + lapse guess.
            const double seen = normal_cdf((std::abs(delta) - 2.0) / 0.5);
            const double expected = 0.96 * (seen + (1 - seen) * guess) + 0.04 * guess;
            EXPECT_NEAR(correct / 40000.0, expected, 0.008) << delta << " " << guess;
            EXPECT_NEAR(o.p_correct(delta, guess), expected, 1e-12);
        }
    for (const char* bad : {"2", "2,0", "-1,0.5", "2,0.5,1.5", "x,1"})
        EXPECT_THROW(DetectionObserver::parse(bad), std::invalid_argument) << bad;
}

TEST(SimulatedObserver, MatchesCarryTheirBiasOnTheKnobsScale) {
    std::mt19937_64 rng(3);
    const MatchObserver linear{1.5, 0.5, false};
    double sum = 0;
    for (int i = 0; i < 20000; ++i) sum += simulated_match(linear, 10, 0, 100, rng);
    EXPECT_NEAR(sum / 20000, 11.5, 0.02);  // SE 0.5 / sqrt(20000) = 0.0035
    // A multiplicative bias: the log of the match averages log(target) + bias.
    const MatchObserver log_scale{std::log(1.25), 0.1, true};
    double log_sum = 0;
    for (int i = 0; i < 20000; ++i)
        log_sum += std::log(simulated_match(log_scale, 16, 1, 64, rng));
    EXPECT_NEAR(log_sum / 20000, std::log(20.0), 0.005);
    // Clamped to the knob's range.
    EXPECT_EQ(simulated_match({100, 0, false}, 10, 0, 64, rng), 64);
    EXPECT_EQ(simulated_match({-100, 0, false}, 10, 0, 64, rng), 0);
}

}  // namespace
}  // namespace lucent::study
