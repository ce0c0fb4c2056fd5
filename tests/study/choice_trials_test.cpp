// Forced-choice trials (issue 30): the protocol's pair, triad and quadruple blocks, the
// designs they generate, and how a SQLite store keeps, exports and merges the choices.
// Expected counts are combinatorics (C(n, k)), written out, never the planner's output.
#include "study/trials/choice/choice_trials.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

#include "common/csv.h"
#include "study/export.h"
#include "study/observations.h"
#include "study/protocol.h"
#include "study/sqlite/sqlite_store.h"
#include "study/trial_plan.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

// The choice protocol with `from` replaced by `to` (once).
std::string edited(const std::string& from, const std::string& to) {
    std::string text = lucent::test::kChoiceProtocol;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
}

const Block& block(const Protocol& p, const std::string& id) {
    const Block* b = p.find_block(id);
    EXPECT_NE(b, nullptr);
    return *b;
}

TEST(ChoiceProtocol, ReadsEachBlocksTaskAndItsKeys) {
    const Protocol p = lucent::test::choice_protocol();
    EXPECT_EQ(block(p, "ratings").task, Task::rating);
    const Block& pairs = block(p, "pairs");
    EXPECT_EQ(pairs.task, Task::pair);
    EXPECT_EQ(pairs.question_id, "more_translucent");
    EXPECT_EQ(pairs.labels, (std::vector<std::string>{"left", "right"}));
    EXPECT_EQ(pairs.presentation, Presentation::side_by_side);
    EXPECT_EQ(pairs.identical_catch, 2);
    EXPECT_EQ(pairs.obvious_catch_repeats, 1);
    const Block& mlds = block(p, "mlds");
    EXPECT_EQ(mlds.task, Task::triad);
    EXPECT_EQ(mlds.question_id, "mlds");  // the block id by default
    EXPECT_EQ(mlds.presentation, Presentation::sequential);
    EXPECT_EQ(mlds.duration_ms, 800);
    EXPECT_EQ(mlds.blank_ms, 300);
    EXPECT_EQ(mlds.labels, (std::vector<std::string>{"first pair", "second pair"}));
    // A pair in sequence has no left and right.
    const Protocol sequential =
        parse_protocol(edited("identical_catch = 2",
                              "identical_catch = 2\npresentation = \"sequential\""),
                       "sequential.toml");
    EXPECT_EQ(block(sequential, "pairs").labels,
              (std::vector<std::string>{"first", "second"}));
}

TEST(ChoiceProtocol, AStudyOfChoicesOnlyNeedsNoQuestions) {
    std::string text = lucent::test::kChoiceProtocol;
    const size_t q = text.find("[[questions]]");
    text.erase(q, text.find("[[stimuli]]") - q);
    const size_t r = text.find("[[blocks]]\nid = \"ratings\"");
    text.erase(r, text.find("[[blocks]]\nid = \"pairs\"") - r);
    EXPECT_NO_THROW(parse_protocol(text, "choices_only.toml"));
    // With the rating block back, the questions are required again.
    std::string with_ratings = text + "\n[[blocks]]\nid = \"r\"\nstimuli = [\"s1\"]\n";
    EXPECT_NE(
        test::protocol_error_of(with_ratings).find("[[questions]] entry is required"),
        std::string::npos);
}

TEST(ChoiceProtocol, RefusesEachBadKeyInOneLineNamingIt) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {edited("task = \"pair\"", "task = \"pairs\""), "key 'blocks.task'"},
        {edited("question = \"Which looks more translucent?\"\n", ""),
         "key 'blocks.question': is required"},
        {edited("question_id = \"more_translucent\"", "question_id = \"translucent\""),
         "already a [[questions]] id"},
        {edited("identical_catch = 2",
                "identical_catch = 2\ndesign = \"cyclic\"\n"
                "neighbours = 3"),
         "1 <= neighbours <= 2"},
        {edited("presentation = \"sequential\"", "identical_catch = 1"),
         "only pair blocks have identical-pair catch trials"},
        {edited("task = \"triad\"\nstimuli = [\"s1\", \"s2\", \"s3\", \"s4\", \"s5\"]",
                "task = \"triad\"\nstimuli = [\"s1\", \"s3\", \"s2\", \"s4\", \"s5\"]"),
         "increasing 'thickness_exponent'"},
        {edited("task = \"triad\"\nstimuli = [\"s1\", \"s2\", \"s3\", \"s4\", \"s5\"]",
                "task = \"quadruple\"\nstimuli = [\"s1\", \"s2\", \"s3\"]"),
         "at least 4 stimuli"},
        {edited("obvious_catch = [\"s5\", \"s1\"]", "obvious_catch = [\"s5\", \"s5\"]"),
         "two different stimuli"},
        {edited("presentation = \"sequential\"", "presentation = \"stacked\""),
         "key 'blocks.presentation'"},
        {edited("task = \"triad\"", "task = \"triad\"\ndesign = \"cyclic\""),
         "must be \"all\" for a triad block"},
    };
    for (const auto& [text, expected] : cases) {
        const std::string error = test::protocol_error_of(text);
        EXPECT_NE(error.find(expected), std::string::npos) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
        EXPECT_EQ(error.rfind("bad.toml:", 0), 0u) << error;
    }
}

// Index of each stimulus in the block's series.
std::map<std::string, int> series_index(const Block& b) {
    std::map<std::string, int> out;
    for (int i = 0; i < static_cast<int>(b.stimuli.size()); ++i) out[b.stimuli[i]] = i;
    return out;
}

TEST(ChoiceDesign, EveryPairTwiceOncePerScreenOrderThenTheCatchTrials) {
    const Protocol p = lucent::test::choice_protocol();
    std::mt19937_64 rng(7);
    const std::vector<PlannedTrial> trials = choice_block_trials(block(p, "pairs"), rng);
    // C(5, 2) = 10 pairs, twice each, + 2 identical + 1 obvious.
    ASSERT_EQ(trials.size(), 23u);
    std::map<std::pair<std::string, std::string>, int> ordered;
    int identical = 0, obvious = 0;
    for (const PlannedTrial& t : trials) {
        ASSERT_EQ(t.shown.size(), 2u);
        EXPECT_EQ(t.task, Task::pair);
        EXPECT_EQ(t.stimulus, t.shown[0]);
        if (t.is_catch && t.catch_id == "identical") {
            EXPECT_EQ(t.shown[0], t.shown[1]);
            EXPECT_EQ(t.expected, 0);  // no right answer
            ++identical;
        } else if (t.is_catch) {
            // "s1" is the high end: the right answer is its position on screen.
            EXPECT_EQ(t.shown[t.expected - 1], "s1");
            EXPECT_EQ(t.shown[2 - t.expected], "s5");
            ++obvious;
        } else {
            EXPECT_NE(t.shown[0], t.shown[1]);
            ++ordered[{t.shown[0], t.shown[1]}];
        }
    }
    EXPECT_EQ(identical, 2);
    EXPECT_EQ(obvious, 1);
    EXPECT_EQ(ordered.size(), 20u);  // each of the 10 pairs in both orders
    for (const auto& [pair, n] : ordered) EXPECT_EQ(n, 1) << pair.first << pair.second;
}

TEST(ChoiceDesign, OneRepeatBalancesTheSidesOverThePairs) {
    Protocol p = lucent::test::choice_protocol();
    Block b = block(p, "pairs");
    b.repeats = 1;
    b.identical_catch = 0;
    b.obvious_catch.clear();
    b.obvious_catch_repeats = 0;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
        std::mt19937_64 rng(seed);
        const std::vector<PlannedTrial> trials = choice_block_trials(b, rng);
        ASSERT_EQ(trials.size(), 10u);
        const std::map<std::string, int> index = series_index(b);
        int flipped = 0;
        std::set<std::set<std::string>> pairs;
        for (const PlannedTrial& t : trials) {
            flipped += index.at(t.shown[0]) > index.at(t.shown[1]) ? 1 : 0;
            pairs.insert({t.shown[0], t.shown[1]});
        }
        EXPECT_EQ(pairs.size(), 10u);
        EXPECT_EQ(flipped, 5) << "seed " << seed;  // 10 pairs: exactly half each way
    }
}

TEST(ChoiceDesign, ACyclicDesignIsBalancedAndConnected) {
    Protocol p = lucent::test::choice_protocol();
    Block b = block(p, "pairs");
    b.stimuli = {"s1", "s2", "s3", "s4", "s5", "a6", "a7", "a8"};
    b.design = "cyclic";
    b.neighbours = 2;
    b.repeats = 1;
    b.identical_catch = 0;
    b.obvious_catch.clear();
    b.obvious_catch_repeats = 0;
    std::mt19937_64 rng(3);
    const std::vector<PlannedTrial> trials = choice_block_trials(b, rng);
    // n = 8, neighbours 2: 8 * 2 = 16 distinct pairs, every stimulus in 4.
    ASSERT_EQ(trials.size(), 16u);
    std::set<std::set<std::string>> pairs;
    std::map<std::string, int> degree;
    std::map<std::string, std::string> parent;  // union-find: one component
    std::function<std::string(const std::string&)> root = [&](const std::string& x) {
        if (!parent.count(x)) parent[x] = x;
        return parent[x] == x ? x : parent[x] = root(parent[x]);
    };
    for (const PlannedTrial& t : trials) {
        pairs.insert({t.shown[0], t.shown[1]});
        ++degree[t.shown[0]];
        ++degree[t.shown[1]];
        parent[root(t.shown[0])] = root(t.shown[1]);
    }
    EXPECT_EQ(pairs.size(), 16u);
    for (const std::string& s : b.stimuli) EXPECT_EQ(degree[s], 4) << s;
    std::set<std::string> roots;
    for (const std::string& s : b.stimuli) roots.insert(root(s));
    EXPECT_EQ(roots.size(), 1u);

    // n even with neighbours n/2: the opposite pairs come once, not twice.
    b.neighbours = 4;
    std::mt19937_64 rng2(3);
    const std::vector<PlannedTrial> all = choice_block_trials(b, rng2);
    std::set<std::set<std::string>> distinct;
    for (const PlannedTrial& t : all) distinct.insert({t.shown[0], t.shown[1]});
    EXPECT_EQ(all.size(), 28u);  // C(8, 2): every pair once
    EXPECT_EQ(distinct.size(), 28u);
}

TEST(ChoiceDesign, TriadsAndQuadruplesAreMldsNonOverlappingGroupsEitherWayRound) {
    const Protocol p = lucent::test::choice_protocol();
    Block b = block(p, "mlds");
    b.stimuli = {"s1", "s2", "s3", "s4", "s5", "a6", "a7", "a8"};
    b.obvious_catch.clear();
    b.obvious_catch_repeats = 0;
    const std::map<std::string, int> index = series_index(b);
    std::mt19937_64 rng(11);
    const std::vector<PlannedTrial> triads = choice_block_trials(b, rng);
    ASSERT_EQ(triads.size(), 56u);  // C(8, 3)
    std::set<std::vector<int>> groups;
    int backwards = 0;
    for (const PlannedTrial& t : triads) {
        ASSERT_EQ(t.shown.size(), 3u);
        std::vector<int> g = {index.at(t.shown[0]), index.at(t.shown[1]),
                              index.at(t.shown[2])};
        // Forwards a < b < c, or backwards c > b > a: the middle is the shared one.
        const bool forwards = g[0] < g[1] && g[1] < g[2];
        EXPECT_TRUE(forwards || (g[0] > g[1] && g[1] > g[2]));
        backwards += forwards ? 0 : 1;
        std::sort(g.begin(), g.end());
        groups.insert(g);
    }
    EXPECT_EQ(groups.size(), 56u);
    EXPECT_EQ(backwards, 28);

    b.task = Task::quadruple;
    std::mt19937_64 rng2(11);
    const std::vector<PlannedTrial> quads = choice_block_trials(b, rng2);
    ASSERT_EQ(quads.size(), 70u);  // C(8, 4)
    std::set<std::vector<int>> quad_groups;
    int second_first = 0;
    for (const PlannedTrial& t : quads) {
        std::vector<int> g;
        for (const std::string& s : t.shown) g.push_back(index.at(s));
        // Two pairs, each increasing; the lower pair first or second.
        EXPECT_LT(g[0], g[1]);
        EXPECT_LT(g[2], g[3]);
        EXPECT_TRUE(g[1] < g[2] || g[3] < g[0]);
        second_first += g[3] < g[0] ? 1 : 0;
        std::sort(g.begin(), g.end());
        quad_groups.insert(g);
    }
    EXPECT_EQ(quad_groups.size(), 70u);
    EXPECT_EQ(second_first, 35);
}

TEST(ChoiceDesign, AnMldsObviousCatchPutsTheRightAnswerOnTheDifferingPair) {
    const Protocol p = lucent::test::choice_protocol();
    for (Task task : {Task::triad, Task::quadruple}) {
        Block b = block(p, "mlds");
        b.task = task;
        b.obvious_catch_repeats = 6;
        std::mt19937_64 rng(5);
        int catches = 0;
        for (const PlannedTrial& t : choice_block_trials(b, rng)) {
            if (!t.is_catch) continue;
            ++catches;
            // The pairs on screen: (0, 1) and (1, 2) for a triad, (0, 1) and (2, 3).
            const std::pair<std::string, std::string> first{t.shown[0], t.shown[1]};
            const std::pair<std::string, std::string> second =
                task == Task::triad ? std::make_pair(t.shown[1], t.shown[2])
                                    : std::make_pair(t.shown[2], t.shown[3]);
            const auto& right = t.expected == 1 ? first : second;
            const auto& wrong = t.expected == 1 ? second : first;
            EXPECT_NE(right.first, right.second);
            EXPECT_EQ(wrong.first, wrong.second);
        }
        EXPECT_EQ(catches, 6);
    }
}

TEST(ChoicePlan, PracticeComesFirstAndTheSameSeedGivesTheSamePlan) {
    const Protocol p = lucent::test::choice_protocol();
    const TrialPlan plan = plan_trials(p, 42, 3);
    // 3 ratings + 23 pair trials + C(5, 3) = 10 triads + 1 obvious catch + 1 practice.
    ASSERT_EQ(plan.trials.size(), 38u);
    EXPECT_TRUE(plan.trials[0].practice);
    EXPECT_EQ(plan.trials[0].task, Task::pair);
    EXPECT_EQ(plan.trials[0].block, "pairs");
    int practice = 0;
    std::map<std::string, int> per_block;
    for (const PlannedTrial& t : plan.trials) {
        practice += t.practice ? 1 : 0;
        if (!t.practice) ++per_block[t.block];
        if (t.task == Task::rating) EXPECT_TRUE(t.shown.empty());
    }
    EXPECT_EQ(practice, 1);
    EXPECT_EQ(per_block["ratings"], 3);
    EXPECT_EQ(per_block["pairs"], 23);
    EXPECT_EQ(per_block["mlds"], 11);
    const TrialPlan again = plan_trials(p, 42, 3);
    for (size_t i = 0; i < plan.trials.size(); ++i) {
        EXPECT_EQ(again.trials[i].shown, plan.trials[i].shown);
        EXPECT_EQ(again.trials[i].stimulus, plan.trials[i].stimulus);
    }
}

TEST(ChoicePlan, TheSequenceConstraintsKeepOnePairFromFollowingItself) {
    std::string text = lucent::test::kChoiceProtocol;
    text += "\n[randomisation]\nmax_repeat = 1\n";
    const Protocol p = parse_protocol(text, "constrained.toml");
    for (uint64_t seed = 1; seed <= 10; ++seed) {
        const TrialPlan plan = plan_trials(p, seed, 0);
        for (size_t i = 1; i < plan.trials.size(); ++i) {
            const PlannedTrial& a = plan.trials[i - 1];
            const PlannedTrial& b = plan.trials[i];
            if (a.practice || b.practice || a.shown.empty() || b.shown.empty()) continue;
            std::multiset<std::string> sa(a.shown.begin(), a.shown.end());
            std::multiset<std::string> sb(b.shown.begin(), b.shown.end());
            EXPECT_NE(sa, sb) << "seed " << seed << " position " << i;
        }
    }
}

// Reads a CSV into rows of cells (header first).
std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        rows.push_back(common::split_csv_line(line));
    return rows;
}

TEST(ChoiceStore, KeepsTheChoicesInScreenOrderAndExportsOneRowEach) {
    const auto dir = lucent::test::scratch_dir("choice_store");
    const std::string path = (dir / "study.db").string();
    const Protocol p = lucent::test::choice_protocol();
    {
        Store store(path);
        const int64_t session = lucent::test::run_full_session(store, p, "P1", 9);
        // Read back: each trial's task and stimuli as planned.
        const TrialPlan plan = plan_trials(p, 9, 1);
        const std::vector<TrialRow> rows = store.trials(session);
        ASSERT_EQ(rows.size(), plan.trials.size());
        for (size_t i = 0; i < rows.size(); ++i) {
            EXPECT_EQ(rows[i].task, plan.trials[i].task);
            EXPECT_EQ(rows[i].shown, plan.trials[i].shown);
            EXPECT_EQ(rows[i].expected, plan.trials[i].expected);
        }
    }
    std::ostringstream out;
    const ChoiceExport all = export_choices(path, out);
    const auto rows = csv_rows(out.str());
    // Every choice trial, practice included: 38 - 3 ratings.
    ASSERT_EQ(all.rows, 35);
    ASSERT_EQ(rows.size(), 36u);
    EXPECT_EQ(rows[0].size(), 19u);
    EXPECT_EQ(rows[0][9], "shown_1");
    const TrialPlan plan = plan_trials(p, 9, 1);
    std::map<int, const PlannedTrial*> by_position;
    for (const PlannedTrial& t : plan.trials) by_position[t.position] = &t;
    const std::map<std::string, std::string> value = {
        {"s1", "10"}, {"s2", "15"}, {"s3", "20"}, {"s4", "25"}, {"s5", "30"}};
    for (size_t r = 1; r < rows.size(); ++r) {
        const std::vector<std::string>& row = rows[r];
        const PlannedTrial& t = *by_position.at(std::stoi(row[2]));
        EXPECT_EQ(row[4], task_name(t.task));
        for (size_t k = 0; k < 4; ++k) {
            EXPECT_EQ(row[9 + k], k < t.shown.size() ? t.shown[k] : "");
            EXPECT_EQ(row[13 + k], k < t.shown.size() ? value.at(t.shown[k]) : "");
        }
        const int expected_choice = t.is_catch && t.expected > 0
                                        ? t.expected
                                        : lucent::test::choice_for(t.position);
        EXPECT_EQ(row[17], std::to_string(expected_choice));
        EXPECT_EQ(row[6], t.practice ? "1" : "0");
    }
    // The analysis view: no practice trial.
    std::ostringstream analysis;
    const ChoiceExport view = export_choices(path, analysis, {.analysis = true});
    EXPECT_EQ(view.rows, 34);
    // The same through export_file, as `lucent export --format ...` writes them.
    EXPECT_EQ(export_file(path, "choices", (dir / "choices.csv").string(), false).rows,
              35);
    EXPECT_EQ(
        export_file(path, "choice-analysis", (dir / "analysis.csv").string(), false).rows,
        34);
    // Ratings stay in the rating exports only.
    const StudyObservations read = read_observations(path);
    // 3 rated trials x 1 question x 1 factor
    EXPECT_EQ(common::factor_ratings(read.table).size(), 3u);
}

TEST(ChoiceStore, RefusesAChoiceOutsideItsTwoAnswersOrAnsweredWithRatings) {
    const auto dir = lucent::test::scratch_dir("choice_refusals");
    Store store((dir / "study.db").string());
    const Protocol p = lucent::test::choice_protocol();
    const int64_t study = store.ensure_study(p);
    int number = 0;
    const int64_t participant = store.ensure_participant(study, "P1", &number);
    const SessionRow s =
        store.create_session(study, participant, plan_trials(p, 1, number), 1, {});
    const std::vector<TrialRow> trials = store.trials(s.id);
    const auto choice = std::find_if(trials.begin(), trials.end(), [](const TrialRow& t) {
        return t.task == Task::pair && !t.practice;
    });
    const auto rating = std::find_if(trials.begin(), trials.end(), [](const TrialRow& t) {
        return t.task == Task::rating;
    });
    ASSERT_NE(choice, trials.end());
    ASSERT_NE(rating, trials.end());
    auto answer = [](const std::string& question, int value) {
        TrialOutcome o;
        Response r;
        r.question = question;
        r.rating = value;
        o.responses.push_back(r);
        return o;
    };
    EXPECT_THROW(store.record_trial(s.id, choice->id, answer("more_translucent", 3)),
                 StoreError);
    EXPECT_THROW(store.record_trial(s.id, choice->id, answer("translucent", 1)),
                 StoreError);
    EXPECT_THROW(store.record_trial(s.id, rating->id, answer("more_translucent", 1)),
                 StoreError);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"), 0);
    EXPECT_NO_THROW(store.record_trial(s.id, choice->id, answer("more_translucent", 2)));
    EXPECT_THROW(store.record_trial(s.id, choice->id, answer("more_translucent", 1)),
                 StoreError);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"), 1);
}

TEST(ChoiceStore, AMergeCarriesEveryChoiceOnceWithItsScreenOrder) {
    const auto dir = lucent::test::scratch_dir("choice_merge");
    const Protocol p = lucent::test::choice_protocol();
    const std::string a = (dir / "a.db").string(), b = (dir / "b.db").string();
    {
        Store store(a);
        lucent::test::run_full_session(store, p, "P1", 5);
    }
    {
        Store store(b);
        lucent::test::run_full_session(store, p, "P2", 6);
    }
    const std::string merged = (dir / "merged.db").string();
    merge_databases({a, b}, merged);
    // The merged export is the two inputs' rows, none lost or doubled.
    auto data_rows = [](const std::string& db) {
        std::ostringstream out;
        export_choices(db, out);
        std::vector<std::string> lines;
        std::istringstream in(out.str());
        std::string line;
        std::getline(in, line);  // header
        while (std::getline(in, line)) lines.push_back(line);
        return lines;
    };
    std::vector<std::string> expected = data_rows(a);
    for (const std::string& line : data_rows(b)) expected.push_back(line);
    std::vector<std::string> got = data_rows(merged);
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got.size(), 70u);
    EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace lucent::study
