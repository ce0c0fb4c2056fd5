// Matching and thresholds (issue 31): the protocol's adjust and staircase blocks, the
// plans they make, and a staircase block's procedures rebuilt from stored answers.
// Expected values are the protocol's own numbers worked by hand, closed forms (the
// uniform's moments) and PsychoPy's published track (tests/study/adaptive/PSYCHOPY.md).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "common/number_text.h"
#include "study/adaptive/staircase_block.h"
#include "study/protocol.h"
#include "study/session/session_flow.h"
#include "study/trial_plan.h"
#include "study/trials/adjust/adjust_trials.h"
#include "study/web_series.h"
#include "tests/study/study_fixtures.h"

namespace lucent::study {
namespace {

const char* kMatching = R"toml(
[study]
name = "matching_test"

[[stimuli]]
id = "target"
technique = "empirical"
params = { thickness_exponent = 1.5, backlight = 1.2 }

[[stimuli]]
id = "target2"
technique = "empirical"
params = { thickness_exponent = 3 }

[[stimuli]]
id = "match"
technique = "empirical"
params = { backlight = 0.6 }

[[stimuli]]
id = "picture"
image = "picture.png"

[[blocks]]
id = "m"
task = "adjust"
stimuli = ["target", "target2"]
match = "match"
knob = "thickness_exponent"
range = [0.25, 4.0]
repeats = 3
question = "Turn the right object until it looks like the left one."

[[blocks]]
id = "j"
task = "staircase"
stimuli = ["target", "target2"]
knob = "thickness_exponent"
question = "Which looks more translucent?"

[[blocks.staircases]]
id = "a"
start = 0.8
step_sizes = [0.1, 0.01, 0.001]
n_trials = 20
n_reversals = 4
max_delta = 1
max_trials = 25

[[blocks.staircases]]
id = "q"
method = "quest"
start = 0.5
start_sd = 0.3
n_trials = 12
max_trials = 12
)toml";

Protocol matching() { return parse_protocol(kMatching, "matching.toml"); }

std::string edited(const std::string& from, const std::string& to) {
    std::string text = kMatching;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
}

TEST(MatchingProtocol, ReadsAnAdjustBlockWithItsDefaults) {
    const Protocol p = matching();
    const Block& m = *p.find_block("m");
    EXPECT_EQ(m.task, Task::adjust);
    EXPECT_FALSE(m.is_choice());
    EXPECT_EQ(m.answers(), 1);
    EXPECT_EQ(m.match, "match");
    EXPECT_EQ(m.knob, "thickness_exponent");
    EXPECT_EQ(m.range_min, 0.25);
    EXPECT_EQ(m.range_max, 4.0);
    // A twentieth and a two-hundredth of the range.
    EXPECT_DOUBLE_EQ(m.step, 3.75 / 20);
    EXPECT_DOUBLE_EQ(m.fine_step, 3.75 / 200);
    EXPECT_EQ(m.start, "random");
    EXPECT_EQ(m.question_id, "m");
    // On a log scale the steps are log10 units: log10(16) / 20.
    const Protocol log_protocol = parse_protocol(
        edited("range = [0.25, 4.0]", "range = [0.25, 4.0]\nscale = \"log\""),
        "log.toml");
    const Block& log = *log_protocol.find_block("m");
    EXPECT_NEAR(log.step, std::log10(16.0) / 20, 1e-15);
    // Without a range: the knob's own.
    const Protocol whole_protocol =
        parse_protocol(edited("range = [0.25, 4.0]\n", ""), "whole.toml");
    const Block& whole = *whole_protocol.find_block("m");
    EXPECT_EQ(whole.range_min, 0.0);
    EXPECT_EQ(whole.range_max, 10000.0);
    // A study of adjustments and staircases needs no [[questions]].
    EXPECT_FALSE(p.has_rating_trials());
}

TEST(MatchingProtocol, ReadsAStaircaseBlockAndItsProcedures) {
    const Protocol p = matching();
    const Block& j = *p.find_block("j");
    EXPECT_EQ(j.task, Task::staircase);
    EXPECT_TRUE(j.is_choice());
    EXPECT_EQ(j.pictures(), 2);
    EXPECT_EQ(j.answers(), 2);
    EXPECT_EQ(j.labels, (std::vector<std::string>{"left", "right"}));
    ASSERT_EQ(j.procedures.size(), 2u);
    const Block::Procedure& a = j.procedures[0];
    EXPECT_EQ(a.method, "updown");
    EXPECT_EQ(a.n_up, 1);
    EXPECT_EQ(a.n_down, 3);
    EXPECT_EQ(a.step_sizes, (std::vector<double>{0.1, 0.01, 0.001}));
    EXPECT_EQ(a.max_delta, 1.0);
    const Block::Procedure& q = j.procedures[1];
    EXPECT_EQ(q.method, "quest");
    EXPECT_EQ(q.p_threshold, 0.82);
    // The deltas' room: the standards' largest upward step inside the knob's range
    // [0, 10000] is 10000 - 3; the grid spans twice that in 500 grains.
    EXPECT_EQ(q.max_delta, 9997.0);
    EXPECT_DOUBLE_EQ(q.grain, 2 * 9997.0 / 500);
    // An odd one out: three pictures, three answers, a third by chance.
    const Protocol odd_protocol =
        parse_protocol(edited("knob = \"thickness_exponent\"\nquestion = "
                              "\"Which looks more translucent?\"",
                              "knob = \"thickness_exponent\"\ntrial = "
                              "\"oddity\"\nquestion = \"Which differs?\""),
                       "odd.toml");
    const Block& odd = *odd_protocol.find_block("j");
    EXPECT_EQ(odd.pictures(), 3);
    EXPECT_EQ(odd.answers(), 3);
    EXPECT_EQ(odd.labels, (std::vector<std::string>{"left", "middle", "right"}));
    EXPECT_DOUBLE_EQ(adaptive::guess_rate(odd), 1.0 / 3);
    EXPECT_EQ(odd.procedures[1].p_threshold, 0.75);
}

TEST(MatchingProtocol, RefusesEachBadKeyInOneLineNamingIt) {
    std::string down_from_zero = edited("params = { thickness_exponent = 3 }",
                                        "params = { thickness_exponent = 0 }");
    const std::string question = "question = \"Which looks more translucent?\"";
    down_from_zero.replace(down_from_zero.find(question), question.size(),
                           question + "\ndirection = \"down\"");
    std::string no_procedures = kMatching;
    no_procedures.erase(no_procedures.find("[[blocks.staircases]]"));
    const std::vector<std::pair<std::string, std::string>> cases = {
        {edited("match = \"match\"\n", ""), "key 'blocks.match': is required"},
        {edited("match = \"match\"", "match = \"nobody\""),
         "no stimulus with id 'nobody'"},
        {edited("match = \"match\"", "match = \"picture\""), "must be a live stimulus"},
        {edited("match = \"match\"", "match = \"target\""), "is also a target"},
        {edited("knob = \"thickness_exponent\"\nrange", "knob = \"thickness\"\nrange"),
         "'thickness' is not a knob of technique 'empirical'"},
        {edited("knob = \"thickness_exponent\"\nrange", "knob = \"blur_kernel\"\nrange"),
         "only a scalar knob can be turned"},
        {edited("range = [0.25, 4.0]", "range = [4.0, 0.25]"), "key 'blocks.range'"},
        {edited("range = [0.25, 4.0]", "range = [-1, 4.0]"), "inside the knob's range"},
        {edited("range = [0.25, 4.0]", "range = [0, 4.0]\nscale = \"log\""),
         "a log scale needs a range above 0"},
        {edited("range = [0.25, 4.0]", "range = [0.25, 4.0]\nstart = 5"),
         "key 'blocks.start': must lie in [0.25, 4]"},
        {edited("range = [0.25, 4.0]", "range = [0.25, 4.0]\nstart = \"middle\""),
         "key 'blocks.start'"},
        {edited("range = [0.25, 4.0]", "range = [0.25, 4.0]\nstep = 0"),
         "key 'blocks.step': must be above 0"},
        {edited("task = \"adjust\"", "task = \"adjustment\""), "key 'blocks.task'"},
        {edited("id = \"a\"\nstart = 0.8\n", "id = \"a\"\n"),
         "key 'blocks.staircases.start': is required"},
        {edited("step_sizes = [0.1, 0.01, 0.001]\n", ""),
         "key 'blocks.staircases.step_sizes': is required"},
        {edited("max_trials = 25", "max_trials = 15"),
         "key 'blocks.staircases.max_trials': must be at least n_trials"},
        {edited("method = \"quest\"", "method = \"psi\""),
         "key 'blocks.staircases.method'"},
        {edited("start_sd = 0.3\n", ""), "key 'blocks.staircases.start_sd'"},
        {edited("id = \"q\"", "id = \"a\""), "duplicate staircase id 'a'"},
        {edited("id = \"q\"", "id = \"q/2\""), "must not hold whitespace or '/'"},
        {edited("max_delta = 1", "max_delta = 1\nn_step = 2"),
         "key 'blocks.staircases.n_step': unknown key"},
        {edited("n_trials = 12\nmax", "n_trials = 12\np_threshold = 0.4\nmax"),
         "between the guess rate (0.5) and 1"},
        {down_from_zero, "at the end of the knob's range: no downward delta"},
        {no_procedures, "at least one [[blocks.staircases]] entry is required"},
        {edited("question = \"Which looks more translucent?\"",
                "question = \"Which differs?\"\ntrial = \"oddity\"\npresentation = "
                "\"sequential\""),
         "key 'blocks.presentation': an odd-one-out staircase is shown side by side"},
        {edited("max_delta = 1", "max_delta = 1\nladder_step = 0"),
         "key 'blocks.staircases.ladder_step': unknown key"},
        {edited("range = [0.25, 4.0]", "range = [0.25, 4.0]\nseries_steps = 1"),
         "key 'blocks.series_steps': must lie in [2, 10001]"},
    };
    for (const auto& [text, expected] : cases) {
        const std::string error = test::protocol_error_of(text);
        EXPECT_NE(error.find(expected), std::string::npos) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
        EXPECT_EQ(error.rfind("bad.toml:", 0), 0u) << error;
    }
}

TEST(MatchingPlan, EachTargetRepeatsWithAStartDrawnOnTheBlocksScale) {
    const Protocol p = matching();
    const TrialPlan plan = plan_trials(p, 7, 1);
    std::map<std::string, int> per_target;
    for (const PlannedTrial& t : plan.trials) {
        if (t.block != "m") continue;
        EXPECT_EQ(t.task, Task::adjust);
        EXPECT_EQ(t.shown, (std::vector<std::string>{t.stimulus, "match"}));
        ASSERT_TRUE(t.start_value);
        EXPECT_GE(*t.start_value, 0.25);
        EXPECT_LE(*t.start_value, 4.0);
        ++per_target[t.stimulus];
    }
    EXPECT_EQ(per_target, (std::map<std::string, int>{{"target", 3}, {"target2", 3}}));

    // "random" is uniform on the scale: over 6000 starts the mean and variance of the
    // value (linear) or its logarithm (log) match the uniform's, (a+b)/2 and
    // (b-a)^2/12, within 4 standard errors.
    for (const std::string scale : {"linear", "log"}) {
        Block b = *p.find_block("m");
        b.scale = scale;
        std::mt19937_64 rng(42);
        const double lo = scale == "log" ? std::log(0.25) : 0.25;
        const double hi = scale == "log" ? std::log(4.0) : 4.0;
        double sum = 0, sum2 = 0;
        const int n = 6000;
        // Each start is a point of the browser's series (201 here), the lab's too.
        const std::vector<double> points = adjust_series_values(b);
        ASSERT_EQ(points.size(), 201u);
        for (int i = 0; i < n; ++i) {
            const double v = adjust_start_value(b, rng);
            ASSERT_GE(v, 0.25);
            ASSERT_LE(v, 4.0);
            ASSERT_EQ(v, points[nearest_step(points, v)]);
            const double x = scale == "log" ? std::log(v) : v;
            sum += x;
            sum2 += x * x;
        }
        const double mean = sum / n, var = sum2 / n - mean * mean;
        const double w = hi - lo;
        EXPECT_NEAR(mean, (lo + hi) / 2, 4 * w / std::sqrt(12.0 * n)) << scale;
        // The variance of a uniform's squared deviation is w^4/80 - w^4/144; the 201
        // evenly spaced points' variance is w^2/12 * 202/200.
        EXPECT_NEAR(var, w * w / 12 * 202 / 200,
                    4 * w * w * std::sqrt(1.0 / 80 - 1.0 / 144) / std::sqrt(n))
            << scale;
    }
    Block fixed = *p.find_block("m");
    std::mt19937_64 rng(1);
    fixed.start = "min";
    EXPECT_EQ(adjust_start_value(fixed, rng), 0.25);
    fixed.start = "max";
    EXPECT_EQ(adjust_start_value(fixed, rng), 4.0);
    fixed.start = "1.75";
    EXPECT_EQ(adjust_start_value(fixed, rng), 1.75);
}

TEST(StaircasePlan, SlotsComeInRoundsWithTheComparisonsPlaceBalanced) {
    // A sequence constraint that would reorder any block it could: the staircase
    // block's rounds stay as planned.
    const std::string text =
        std::string(kMatching) + "\n[randomisation]\nmax_repeat = 1\n";
    const Protocol p = parse_protocol(text, "constrained.toml");
    const TrialPlan plan = plan_trials(p, 11, 2);
    std::vector<const PlannedTrial*> slots;
    for (const PlannedTrial& t : plan.trials)
        if (t.block == "j") slots.push_back(&t);
    // 2 standards x (25 + 12) slots.
    ASSERT_EQ(slots.size(), 2u * (25 + 12));
    // Contiguous, after or before the adjust block.
    EXPECT_EQ(slots.back()->position - slots.front()->position, 73);
    std::map<std::string, std::map<int, int>> places;
    for (const PlannedTrial* t : slots) {
        EXPECT_EQ(t->task, Task::staircase);
        EXPECT_EQ(t->shown, (std::vector<std::string>{t->stimulus, t->stimulus}));
        EXPECT_EQ(t->staircase.substr(0, t->stimulus.size() + 1), t->stimulus + "/");
        ++places[t->staircase][t->expected];
    }
    // Each procedure's comparison on each side equally often (25: 12 and 13).
    EXPECT_EQ(places.size(), 4u);
    for (const auto& [label, count] : places) {
        const int total = count.count(1) ? count.at(1) + count.at(2) : 0;
        EXPECT_LE(std::abs(count.at(1) - count.at(2)), total % 2) << label;
    }
    // Rounds: the first 12 rounds hold each of the 4 procedures once, the next 13 the
    // two up/down procedures once.
    for (int round = 0; round < 25; ++round) {
        const int size = round < 12 ? 4 : 2;
        const int begin = round < 12 ? 4 * round : 48 + 2 * (round - 12);
        std::set<std::string> labels;
        for (int i = begin; i < begin + size; ++i) labels.insert(slots[i]->staircase);
        EXPECT_EQ(static_cast<int>(labels.size()), size) << "round " << round;
    }
    // The same seed, the same plan.
    const TrialPlan again = plan_trials(p, 11, 2);
    for (size_t i = 0; i < plan.trials.size(); ++i) {
        EXPECT_EQ(again.trials[i].staircase, plan.trials[i].staircase);
        EXPECT_EQ(again.trials[i].expected, plan.trials[i].expected);
        EXPECT_EQ(again.trials[i].start_value, plan.trials[i].start_value);
    }
}

// Answers in cycles of `correct` right then `wrong` wrong, as PsychoPy's tests give.
bool cycle_answer(int trial, int correct, int wrong) {
    return trial % (correct + wrong) < correct;
}

TEST(StaircaseBlock, RebuiltFromStoredAnswersItGoesOnAsPsychoPys) {
    const Protocol p = matching();
    const Block& j = *p.find_block("j");
    // PsychoPy's linear 1-up/3-down track (test_StairHandlerLinear), through the
    // protocol's keys, with the session stopped and resumed after every trial: each
    // resume replays the stored slots.
    const std::vector<double> track = {0.8,   0.7,   0.6,   0.5,   0.4,   0.41,  0.42,
                                       0.43,  0.44,  0.44,  0.44,  0.439, 0.439, 0.44,
                                       0.441, 0.442, 0.443, 0.443, 0.443, 0.442};
    std::vector<TrialRow> stored;
    for (int i = 0; i < 20; ++i) {
        adaptive::StaircaseBlock block(j);
        block.replay(stored);
        const adaptive::Proposal next = block.propose("target/a");
        EXPECT_NEAR(next.intensity, track[i], 1e-12) << "trial " << i + 1;
        TrialRow row;
        row.position = 100 + i;
        row.block = "j";
        row.staircase = "target/a";
        row.expected = 1 + i % 2;
        row.answered = true;
        row.intensity = next.intensity;
        const bool correct = cycle_answer(i, 4, 4);
        row.choice = correct ? row.expected : 3 - row.expected;
        const bool finished = block.answer("target/a", correct);
        EXPECT_EQ(finished, i == 19) << "trial " << i + 1;
        stored.push_back(row);
    }
    adaptive::StaircaseBlock done(j);
    done.replay(stored);
    EXPECT_TRUE(done.finished("target/a"));
    EXPECT_FALSE(done.finished("target2/a"));
    EXPECT_THROW(done.propose("target/a"), std::logic_error);
    EXPECT_THROW(done.propose("target/b"), std::out_of_range);
    // A stored slot of a procedure that had finished is a damaged record.
    TrialRow extra = stored.back();
    extra.position = 200;
    stored.push_back(extra);
    adaptive::StaircaseBlock damaged(j);
    EXPECT_THROW(damaged.replay(stored), std::runtime_error);
    // So is an answered slot without its delta.
    stored.pop_back();
    stored[3].intensity.reset();
    adaptive::StaircaseBlock no_delta(j);
    EXPECT_THROW(no_delta.replay(stored), std::runtime_error);
}

TEST(StaircaseBlock, AQuestFromTheProtocolIsHeldInsideTheDeltasRange) {
    // Always wrong: QUEST climbs, and is held at the largest delta the knob allows.
    const Protocol p = matching();
    adaptive::StaircaseBlock block(*p.find_block("j"));
    bool finished = false;
    for (int i = 0; i < 12; ++i) {
        const adaptive::Proposal next = block.propose("target2/q");
        EXPECT_TRUE(std::isfinite(next.intensity));
        EXPECT_GE(next.intensity, 0.0);
        EXPECT_LE(next.intensity, 9997.0);
        finished = block.answer("target2/q", false);
    }
    EXPECT_TRUE(finished);
    EXPECT_TRUE(block.procedure("target2/q").hit_range());
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

TEST(MatchingProtocol, TheBrowserShowsEachSeriesFromItsPicturesAndRefusesAStartOffThem) {
    // matching(): range [0.25, 4], linear, fine steps of 3.75 / 200: 201 pictures.
    const Protocol p =
        parse_protocol(std::string(kMatching) + "max_delta = 0.5\n", "m.toml");
    const WebSeries series = web_series(p);
    const KnobSeries* s = series.find("m", p.find_block("m")->match);
    ASSERT_NE(s, nullptr);
    ASSERT_EQ(s->steps.size(), 201u);
    EXPECT_EQ(s->steps.front(), 0.25);
    EXPECT_EQ(s->steps.back(), 4.0);
    EXPECT_NEAR(s->steps[60], 0.25 + 60 * 3.75 / 200, 1e-12);
    EXPECT_EQ(s->pictures[60],
              "match@thickness_exponent=" + common::shortest_text(s->steps[60]));
    // The ladder: the smallest linear step (0.001) from 0 to the largest max_delta (1).
    const KnobSeries* ladder = series.find("j", "target2");
    ASSERT_NE(ladder, nullptr);
    ASSERT_EQ(ladder->steps.size(), 1001u);
    EXPECT_EQ(ladder->pictures.front(), "target2");  // delta 0: the standard itself
    EXPECT_NEAR(ladder->steps[250], 0.25, 1e-12);
    EXPECT_EQ(ladder->pictures[250], "target2@thickness_exponent=3.25");
    EXPECT_EQ(nearest_step(ladder->steps, 0.2504), 250u);
    EXPECT_EQ(nearest_step(ladder->steps, 7.0), 1000u);
    // Each picture is a live stimulus of its own: the base with the knob set.
    const Protocol shown = with_series_pictures(p, series);
    const Stimulus* picture = shown.find_stimulus("target2@thickness_exponent=3.25");
    ASSERT_NE(picture, nullptr);
    EXPECT_EQ(picture->technique, "empirical");
    EXPECT_EQ(shown.numeric_parameter(picture->id, "thickness_exponent"), 3.25);
    EXPECT_EQ(shown.stimuli.size(), p.stimuli.size() + 201 + 2 * 1000);
    // QUEST's delta as far as the knob's range goes: a million rungs, refused.
    try {
        web_series(matching());
        FAIL() << "no refusal";
    } catch (const ProtocolError& e) {
        EXPECT_EQ(std::string(e.what()),
                  std::string("matching.toml: block 'j': the browser's ladder of deltas "
                              "[0, 9997] in steps of 0.001 would be 9997001 pictures per "
                              "standard (at most 2000): set ladder_step or max_delta"));
    }
    // A numeric start off the series.
    try {
        web_series(parse_protocol(
            edited("range = [0.25, 4.0]\n", "range = [0.25, 4.0]\nstart = 0.26\n") +
                "max_delta = 0.5\n",
            "s.toml"));
        FAIL() << "no refusal";
    } catch (const ProtocolError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "s.toml: block 'm': start 0.26 is not one of the browser's 201 series "
                  "values (nearest: 0.26875); change series_steps or the start");
    }
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

TEST(BuiltinMatchingStudies, MatchingAndJndPlanWhatTheirCommentsSay) {
    // matching: three blocks of two targets, each three times, on a log scale 1..100.
    const Protocol matching = builtin_protocol("matching");
    const TrialPlan m = plan_trials(matching, 1, 1);
    int adjust = 0;
    std::set<std::string> matches;
    for (const PlannedTrial& t : m.trials) {
        ASSERT_EQ(t.task, Task::adjust);
        ASSERT_TRUE(t.start_value);
        EXPECT_GE(*t.start_value, 2.5);
        EXPECT_LE(*t.start_value, 100.0);
        matches.insert(t.shown[1]);
        ++adjust;
    }
    EXPECT_EQ(adjust, 3 * 2 * 3);
    EXPECT_EQ(matches, (std::set<std::string>{"match_front", "match_back"}));
    // The cross block's target and match differ in exactly the light's direction.
    const Block& cross = *matching.find_block("cross");
    const Stimulus& match = *matching.find_stimulus(cross.match);
    const Stimulus& target = *matching.find_stimulus(cross.stimuli[0]);
    EXPECT_NE(match.parameters.at("light_direction"),
              target.parameters.at("light_direction"));
    EXPECT_EQ(matching.find_stimulus(matching.find_block("back")->match)
                  ->parameters.at("light_direction"),
              target.parameters.at("light_direction"));

    // jnd: three standards (the thesis's r = 18, 25, 30), each an up/down staircase
    // of at most 60 slots and a QUEST of 40, the comparison below the standard.
    const Protocol jnd = builtin_protocol("jnd");
    const Block& j = *jnd.find_block("jnd");
    EXPECT_EQ(j.direction, "down");
    std::map<std::string, int> slots;
    for (const PlannedTrial& t : plan_trials(jnd, 1, 1).trials) ++slots[t.staircase];
    EXPECT_EQ(slots, (std::map<std::string, int>{{"r_18/quest", 40},
                                                 {"r_18/updown", 60},
                                                 {"r_25/quest", 40},
                                                 {"r_25/updown", 60},
                                                 {"r_30/quest", 40},
                                                 {"r_30/updown", 60}}));
    for (const std::string& standard : j.stimuli)
        EXPECT_GT(*jnd.numeric_parameter(standard, "thickness_exponent"),
                  j.procedures[0].max_delta);  // the comparison's r stays above 0
}

}  // namespace
}  // namespace lucent::study
