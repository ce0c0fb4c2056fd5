// The up/down staircases against PsychoPy's own tests
// (psychopy/tests/test_data/test_StairHandlers.py; tests/study/adaptive/PSYCHOPY.md
// lists each value's source), and the hard cases: log steps refusing non-positive
// values, a staircase held at the knob's range, interleaved staircases.
#include "study/adaptive/staircase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lucent::study::adaptive {
namespace {

// PsychoPy's makeBasicResponseCycles: n_correct ones then n_incorrect zeros, repeated,
// cut to `length`.
std::vector<int> response_cycles(int n_correct, int n_incorrect, int length) {
    std::vector<int> out;
    while (static_cast<int>(out.size()) < length)
        for (int i = 0; i < n_correct + n_incorrect; ++i) out.push_back(i < n_correct);
    out.resize(length);
    return out;
}

// Runs the staircase as PsychoPy's test does (for each trial until finished: next, then
// the scripted response) and returns the number of trials run.
int run(AdaptiveProcedure& stairs, const std::vector<int>& responses) {
    int n = 0;
    while (!stairs.finished()) {
        EXPECT_LT(n, static_cast<int>(responses.size())) << "the staircase ran on";
        if (n >= static_cast<int>(responses.size())) break;
        stairs.next();
        stairs.add_response(responses[n] == 1);
        ++n;
    }
    return n;
}

void expect_track(const Staircase& stairs, const std::vector<int>& responses,
                  const std::vector<double>& intensities,
                  const std::vector<int>& reversal_trials) {
    EXPECT_TRUE(stairs.finished());
    EXPECT_EQ(stairs.responses(), responses);
    ASSERT_EQ(stairs.intensities().size(), intensities.size());
    for (std::size_t i = 0; i < intensities.size(); ++i)
        EXPECT_NEAR(stairs.intensities()[i], intensities[i], 1e-8) << "trial " << i;
    EXPECT_EQ(stairs.reversal_trials(), reversal_trials);
    ASSERT_EQ(stairs.reversal_intensities().size(), reversal_trials.size());
    for (std::size_t i = 0; i < reversal_trials.size(); ++i)
        EXPECT_NEAR(stairs.reversal_intensities()[i], intensities[reversal_trials[i]],
                    1e-8);
    EXPECT_GE(static_cast<int>(stairs.reversal_trials().size()), stairs.n_reversals());
}

StaircaseSettings one_up_three_down(std::vector<double> steps, StepType type) {
    StaircaseSettings s;
    s.start = 0.8;
    s.min_value = 0;
    s.max_value = 1;
    s.step_sizes = std::move(steps);
    s.n_up = 1;
    s.n_down = 3;
    s.n_reversals = 4;
    s.n_trials = 20;
    s.step_type = type;
    return s;
}

// test_StairHandlerLinear (and test_StairHandlerLinearReveralsNone: the same track).
TEST(Staircase, PsychoPyLinearOneUpThreeDown) {
    for (std::optional<int> n_reversals : {std::optional<int>(4), std::optional<int>()}) {
        StaircaseSettings s = one_up_three_down({0.1, 0.01, 0.001}, StepType::lin);
        s.n_reversals = n_reversals;
        Staircase stairs(s);
        const auto responses = response_cycles(4, 4, 20);
        EXPECT_EQ(run(stairs, responses), 20);
        expect_track(stairs, responses,
                     {0.8,  0.7,   0.6,   0.5,  0.4,   0.41,  0.42,  0.43,  0.44,  0.44,
                      0.44, 0.439, 0.439, 0.44, 0.441, 0.442, 0.443, 0.443, 0.443, 0.442},
                     {4, 10, 12, 18});
        EXPECT_FALSE(stairs.hit_range());
        EXPECT_DOUBLE_EQ(stairs.step_size(), 0.001);
    }
}

const std::vector<double> kDbTrack = {0.8,         0.763994069, 0.729608671, 0.696770872,
                                      0.665411017, 0.680910431, 0.696770872, 0.713000751,
                                      0.729608671, 0.729608671, 0.729608671, 0.713000751,
                                      0.713000751, 0.72125691,  0.729608671, 0.738057142,
                                      0.746603441, 0.746603441, 0.746603441, 0.738057142};

// test_StairHandlerDb.
TEST(Staircase, PsychoPyDecibelSteps) {
    Staircase stairs(one_up_three_down({0.4, 0.2, 0.2, 0.1}, StepType::db));
    const auto responses = response_cycles(4, 4, 20);
    EXPECT_EQ(run(stairs, responses), 20);
    expect_track(stairs, responses, kDbTrack, {4, 10, 12, 18});
}

// test_StairHandlerLog: log10 steps of a twentieth of the dB steps give the dB track.
TEST(Staircase, PsychoPyLogSteps) {
    Staircase stairs(
        one_up_three_down({0.4 / 20, 0.2 / 20, 0.2 / 20, 0.1 / 20}, StepType::log));
    const auto responses = response_cycles(4, 4, 20);
    EXPECT_EQ(run(stairs, responses), 20);
    expect_track(stairs, responses, kDbTrack, {4, 10, 12, 18});
}

// test_StairHandlerScalarStepSize and test_StairHandlerLinearScalarStepSizeReveralsNone:
// 1-up/1-down, one step of 0.1; finished at trial 10 with its 6th reversal (given as 6,
// or none given: then 1, and the 10 trials decide).
TEST(Staircase, PsychoPyScalarStepOneUpOneDown) {
    for (std::optional<int> n_reversals : {std::optional<int>(6), std::optional<int>()}) {
        StaircaseSettings s;
        s.start = 0.8;
        s.min_value = 0;
        s.max_value = 1;
        s.step_sizes = {0.1};
        s.n_up = 1;
        s.n_down = 1;
        s.n_reversals = n_reversals;
        s.n_trials = 10;
        s.step_type = StepType::lin;
        Staircase stairs(s);
        const auto responses = response_cycles(2, 1, 10);
        EXPECT_EQ(run(stairs, responses), 10);
        expect_track(stairs, responses,
                     {0.8, 0.7, 0.6, 0.7, 0.6, 0.5, 0.6, 0.5, 0.4, 0.5},
                     {2, 3, 5, 6, 8, 9});
    }
}

// test_nReversals: PsychoPy raises nReversals to the number of step sizes.
TEST(Staircase, PsychoPyReversalsAtLeastTheStepSizes) {
    StaircaseSettings s;
    s.start = 1;
    s.step_sizes = {0, 1, 2, 3, 4};
    EXPECT_EQ(Staircase(s).n_reversals(), 5);
    s.n_reversals = 4;
    EXPECT_EQ(Staircase(s).n_reversals(), 5);
    s.n_reversals = 6;
    EXPECT_EQ(Staircase(s).n_reversals(), 6);
}

// test_applyInitialRule_False: 1-up/2-down from the first trial.
TEST(Staircase, PsychoPyWithoutTheInitialRule) {
    StaircaseSettings s;
    s.start = 10;
    s.step_sizes = {2};
    s.n_reversals = 2;
    s.n_up = 1;
    s.n_down = 2;
    s.apply_initial_rule = false;
    s.step_type = StepType::lin;
    Staircase stairs(s);
    for (int r : {0, 1, 1, 0}) {
        ASSERT_FALSE(stairs.finished());
        stairs.next();
        stairs.add_response(r == 1);
    }
    EXPECT_EQ(stairs.responses(), (std::vector<int>{0, 1, 1, 0}));
    EXPECT_EQ(stairs.intensities(), (std::vector<double>{10, 12, 12, 10}));
}

// Needs both stop rules: 20 trials of a 1-up/1-down that never reverses keep going
// until the reversals come.
TEST(Staircase, FinishesOnlyWhenTrialsAndReversalsAreBothMet) {
    StaircaseSettings s;
    s.start = 5;
    s.step_sizes = {1};
    s.step_type = StepType::lin;
    s.n_up = 1;
    s.n_down = 1;
    s.n_trials = 3;
    s.n_reversals = 2;
    Staircase stairs(s);
    for (int i = 0; i < 6; ++i) {
        stairs.next();
        stairs.add_response(true);  // always down: no reversal
        EXPECT_FALSE(stairs.finished());
    }
    stairs.next();
    stairs.add_response(false);  // reversal 1
    EXPECT_FALSE(stairs.finished());
    stairs.next();
    stairs.add_response(true);  // reversal 2, 8 trials
    EXPECT_TRUE(stairs.finished());
    EXPECT_EQ(stairs.reversal_trials(), (std::vector<int>{6, 7}));
    EXPECT_THROW(stairs.next(), std::logic_error);
}

// A staircase at maxVal keeps proposing maxVal and says it was held there.
TEST(Staircase, AtMaxValKeepsProposingMaxValAndReportsClamped) {
    StaircaseSettings s;
    s.start = 0.9;
    s.min_value = 0;
    s.max_value = 1;
    s.step_sizes = {0.3};
    s.step_type = StepType::lin;
    s.n_up = 1;
    s.n_down = 3;
    s.n_trials = 8;
    Staircase stairs(s);
    EXPECT_EQ(stairs.next().intensity, 0.9);
    stairs.add_response(false);
    for (int i = 1; i < 8; ++i) {
        const Proposal p = stairs.next();
        EXPECT_EQ(p.intensity, 1.0) << "trial " << i;
        EXPECT_TRUE(p.clamped) << "trial " << i;
        stairs.add_response(false);
    }
    EXPECT_TRUE(stairs.hit_range());
    EXPECT_FALSE(stairs.clamped_trials()[0]);
    EXPECT_TRUE(stairs.clamped_trials()[7]);
    // Going down from the bound is not held.
    stairs.next();
    stairs.add_response(true);
    EXPECT_FALSE(stairs.upcoming().clamped);
    EXPECT_NEAR(stairs.upcoming().intensity, 0.7, 1e-12);
}

TEST(Staircase, AtMinValHoldsWithDbSteps) {
    StaircaseSettings s;
    s.start = 0.011;
    s.min_value = 0.01;
    s.step_sizes = {6};
    s.n_trials = 3;
    Staircase stairs(s);
    stairs.next();
    stairs.add_response(true);
    const Proposal p = stairs.next();
    EXPECT_EQ(p.intensity, 0.01);
    EXPECT_TRUE(p.clamped);
}

// Log and dB steps refuse non-positive values, with one line naming the parameter.
TEST(Staircase, LogStepsRefuseNonPositiveStart) {
    for (StepType type : {StepType::log, StepType::db}) {
        for (double start : {0.0, -0.5}) {
            StaircaseSettings s;
            s.start = start;
            s.step_type = type;
            try {
                Staircase stairs(s);
                FAIL() << "accepted start " << start;
            } catch (const std::invalid_argument& e) {
                const std::string what = e.what();
                EXPECT_NE(what.find("startVal"), std::string::npos) << what;
                EXPECT_NE(what.find(std::string(to_string(type))), std::string::npos);
                EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            }
        }
    }
    StaircaseSettings lin;
    lin.start = 0;
    lin.step_type = StepType::lin;
    EXPECT_NO_THROW(Staircase{lin});
}

TEST(Staircase, RefusesBadSettingsNamingTheParameter) {
    auto message = [](StaircaseSettings s) {
        try {
            Staircase stairs(std::move(s));
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    StaircaseSettings base;
    base.start = 1;
    StaircaseSettings s = base;
    s.step_sizes = {};
    EXPECT_NE(message(s).find("stepSizes"), std::string::npos);
    s = base;
    s.step_sizes = {1, -1};
    EXPECT_NE(message(s).find("stepSizes"), std::string::npos);
    s = base;
    s.n_down = 0;
    EXPECT_NE(message(s).find("nDown"), std::string::npos);
    s = base;
    s.n_up = 0;
    EXPECT_NE(message(s).find("nUp"), std::string::npos);
    s = base;
    s.min_value = 2;
    s.max_value = 1;
    EXPECT_NE(message(s).find("minVal"), std::string::npos);
    s = base;
    s.max_value = 0.5;
    EXPECT_NE(message(s).find("outside"), std::string::npos);
    s = base;
    s.start = std::nan("");
    EXPECT_NE(message(s).find("startVal"), std::string::npos);
    EXPECT_THROW(parse_step_type("linear"), std::invalid_argument);
    EXPECT_EQ(parse_step_type("db"), StepType::db);
}

TEST(Staircase, TrialsAlternateWithResponses) {
    StaircaseSettings s;
    s.start = 1;
    Staircase stairs(s);
    EXPECT_THROW(stairs.add_response(true), std::logic_error);
    stairs.next();
    EXPECT_THROW(stairs.next(), std::logic_error);
    EXPECT_THROW(stairs.add_response(true, std::nan("")), std::invalid_argument);
    stairs.add_response(true, 0.95);  // the ladder's nearest step was shown
    EXPECT_EQ(stairs.intensities(), (std::vector<double>{0.95}));
}

// PsychoPy: the shown intensity replaces the record, the staircase steps on from its
// own proposal.
TEST(Staircase, ShownIntensityIsRecordedButStepsFollowTheProposal) {
    StaircaseSettings s;
    s.start = 0.5;
    s.step_sizes = {0.1};
    s.step_type = StepType::lin;
    Staircase stairs(s);
    stairs.next();
    stairs.add_response(true, 0.52);
    EXPECT_NEAR(stairs.next().intensity, 0.4, 1e-12);
    stairs.add_response(false, 0.41);
    EXPECT_EQ(stairs.reversal_intensities(), (std::vector<double>{0.41}));
}

std::unique_ptr<AdaptiveProcedure> linear_stairs(double start) {
    StaircaseSettings s = one_up_three_down({0.1, 0.01, 0.001}, StepType::lin);
    s.start = start;
    return std::make_unique<Staircase>(s);
}

// Two identical staircases given identical answers stay identical whichever order
// they run in (as test_multiStairQuestSequentialIdenticalConditions), each equal to
// the single staircase of test_StairHandlerLinear.
TEST(Interleaved, RoutesEachResponseToItsStaircase) {
    for (InterleaveOrder order : {InterleaveOrder::sequential, InterleaveOrder::random}) {
        std::vector<std::unique_ptr<AdaptiveProcedure>> list;
        list.push_back(linear_stairs(0.8));
        list.push_back(linear_stairs(0.8));
        Interleaved stairs(std::move(list), 7, order);
        const auto responses = response_cycles(4, 4, 20);
        std::vector<int> trial_of(2, 0);
        while (!stairs.finished()) {
            const Interleaved::Trial t = stairs.next();
            stairs.add_response(responses[trial_of[t.procedure]++] == 1);
        }
        EXPECT_EQ(stairs.total_trials(), 40u);
        for (std::size_t i = 0; i < 2; ++i)
            expect_track(
                static_cast<const Staircase&>(stairs.procedure(i)), responses,
                {0.8,  0.7,   0.6,   0.5,  0.4,   0.41,  0.42,  0.43,  0.44,  0.44,
                 0.44, 0.439, 0.439, 0.44, 0.441, 0.442, 0.443, 0.443, 0.443, 0.442},
                {4, 10, 12, 18});
    }
}

// 'random': each round a shuffle of the running staircases (each once per round), the
// same for the same seed; a finished staircase leaves the rounds.
TEST(Interleaved, RandomOrderIsAShuffledRoundAndSeeded) {
    auto make = [](std::uint64_t seed) {
        std::vector<std::unique_ptr<AdaptiveProcedure>> list;
        for (int i = 0; i < 3; ++i) {
            StaircaseSettings s;
            s.start = 1;
            s.step_sizes = {1};
            s.n_trials = 4 + 2 * i;  // finish at different times
            s.n_reversals = 1;
            s.n_up = 1;
            s.n_down = 1;
            s.step_type = StepType::lin;
            list.push_back(std::make_unique<Staircase>(s));
        }
        return Interleaved(std::move(list), seed, InterleaveOrder::random);
    };
    auto order_of = [](Interleaved stairs) {
        std::vector<std::size_t> order;
        bool answer = false;
        while (!stairs.finished()) {
            order.push_back(stairs.next().procedure);
            stairs.add_response(answer = !answer);
        }
        return order;
    };
    const auto a = order_of(make(11));
    EXPECT_EQ(a, order_of(make(11)));
    EXPECT_EQ(a.size(), 4u + 6u + 8u);
    // The first three rounds hold each staircase once.
    for (std::size_t round = 0; round < 3; ++round) {
        std::vector<std::size_t> r(a.begin() + 3 * round, a.begin() + 3 * round + 3);
        std::sort(r.begin(), r.end());
        EXPECT_EQ(r, (std::vector<std::size_t>{0, 1, 2})) << "round " << round;
    }
    bool some_seed_differs = false;
    for (std::uint64_t seed = 1; seed < 6; ++seed)
        some_seed_differs |= order_of(make(seed)) != a;
    EXPECT_TRUE(some_seed_differs);
    EXPECT_THROW(parse_interleave_order("linear"), std::invalid_argument);
}

TEST(Interleaved, FullRandomSkipsFinishedStaircases) {
    std::vector<std::unique_ptr<AdaptiveProcedure>> list;
    list.push_back(linear_stairs(0.8));
    list.push_back(linear_stairs(0.6));
    Interleaved stairs(std::move(list), 3, InterleaveOrder::full_random);
    const auto responses = response_cycles(4, 4, 1000);
    std::vector<int> trial_of(2, 0);
    int n = 0;
    while (!stairs.finished() && n++ < 1000) {
        const Interleaved::Trial t = stairs.next();
        stairs.add_response(responses[trial_of[t.procedure]++] == 1);
    }
    EXPECT_EQ(trial_of, (std::vector<int>{20, 20}));
    EXPECT_TRUE(stairs.finished());
    EXPECT_TRUE(stairs.procedure(0).finished());
    EXPECT_TRUE(stairs.procedure(1).finished());
    EXPECT_THROW(stairs.next(), std::logic_error);
}

}  // namespace
}  // namespace lucent::study::adaptive
