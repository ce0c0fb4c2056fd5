// Trial planning: Latin-square balance, constrained shuffles over many seeds, and
// impossible constraints reported instead of searched forever.
#include "trial_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <random>
#include <set>

#include "study_fixtures.h"

namespace lucent::study {
namespace {

// Independent check of the constraints: longest run and closest pair of equal levels.
int longest_run(const std::vector<std::string>& s) {
    int best = 0, run = 0;
    for (size_t i = 0; i < s.size(); ++i) {
        run = (i > 0 && s[i] == s[i - 1]) ? run + 1 : 1;
        best = std::max(best, run);
    }
    return best;
}
int closest_repeat(const std::vector<std::string>& s) {
    int best = 1 << 30;
    for (size_t i = 0; i < s.size(); ++i)
        for (size_t j = i + 1; j < s.size(); ++j)
            if (s[i] == s[j]) best = std::min(best, static_cast<int>(j - i));
    return best;
}

TEST(LatinSquare, EveryConditionOncePerPositionAndEachOrderedPairEquallyOften) {
    for (int n = 1; n <= 8; ++n) {
        const int rows = latin_square_rows(n);
        std::vector<std::vector<int>> position_count(n, std::vector<int>(n, 0));
        std::map<std::pair<int, int>, int> adjacent;
        for (int participant = 0; participant < rows; ++participant) {
            const std::vector<int> row = latin_square_row(n, participant);
            ASSERT_EQ(static_cast<int>(row.size()), n);
            EXPECT_EQ(std::set<int>(row.begin(), row.end()).size(), static_cast<size_t>(n));
            for (int pos = 0; pos < n; ++pos) ++position_count[row[pos]][pos];
            for (int pos = 0; pos + 1 < n; ++pos) ++adjacent[{row[pos], row[pos + 1]}];
        }
        for (int c = 0; c < n; ++c)
            for (int pos = 0; pos < n; ++pos)
                EXPECT_EQ(position_count[c][pos], rows / n) << "n=" << n;
        // Williams design: each ordered pair (a, b), a != b, adjacent equally often.
        if (n > 1) {
            EXPECT_EQ(adjacent.size(), static_cast<size_t>(n * (n - 1))) << "n=" << n;
            for (const auto& [pair, count] : adjacent)
                EXPECT_EQ(count, rows / n) << "n=" << n << " pair " << pair.first << ","
                                           << pair.second;
        }
    }
}

TEST(LatinSquare, ParticipantNumbersWrapAround) {
    EXPECT_EQ(latin_square_row(4, 1), latin_square_row(4, 5));
    EXPECT_EQ(latin_square_row(3, 0), latin_square_row(3, 6));
    EXPECT_NE(latin_square_row(3, 0), latin_square_row(3, 3));
}

TEST(ConstrainedShuffle, ConstraintsHoldOverManySeeds) {
    std::mt19937 gen(7);
    for (int trial = 0; trial < 300; ++trial) {
        // A random block: 3-5 levels, 2-4 trials each.
        std::vector<std::string> levels;
        const int n_levels = 3 + trial % 3;
        for (int l = 0; l < n_levels; ++l)
            for (int k = 0; k < 2 + (trial + l) % 3; ++k) levels.push_back("L" + std::to_string(l));
        const SequenceConstraints c{1 + trial % 2, trial % 3 == 0 ? 2 : 0};
        const std::vector<int> perm = constrained_shuffle(levels, c, gen());
        std::vector<int> sorted = perm;
        std::sort(sorted.begin(), sorted.end());
        for (int i = 0; i < static_cast<int>(sorted.size()); ++i) ASSERT_EQ(sorted[i], i);
        std::vector<std::string> seq;
        for (int i : perm) seq.push_back(levels[i]);
        EXPECT_LE(longest_run(seq), c.max_repeat);
        if (c.min_distance > 0) {
            EXPECT_GE(closest_repeat(seq), c.min_distance);
        }
    }
}

TEST(ConstrainedShuffle, DifferentSeedsGiveDifferentOrdersAndTheSameSeedTheSame) {
    std::vector<std::string> levels;
    for (int i = 0; i < 12; ++i) levels.push_back(std::to_string(i % 4));
    const SequenceConstraints c{1, 0};
    std::set<std::vector<int>> orders;
    for (uint64_t seed = 0; seed < 50; ++seed) orders.insert(constrained_shuffle(levels, c, seed));
    EXPECT_GT(orders.size(), 40u);
    EXPECT_EQ(constrained_shuffle(levels, c, 99), constrained_shuffle(levels, c, 99));
}

TEST(ConstrainedShuffle, ImpossibleConstraintsAreReportedQuickly) {
    const auto start = std::chrono::steady_clock::now();
    // Four 'a' among six trials cannot avoid adjacent 'a's.
    EXPECT_THROW(constrained_shuffle({"a", "a", "a", "a", "b", "c"}, {1, 0}, 1), PlanError);
    // Three 'a' at distance >= 3 need 7 positions.
    EXPECT_THROW(constrained_shuffle({"a", "a", "a", "b", "c", "d"}, {0, 3}, 1), PlanError);
    try {
        constrained_shuffle({"x", "x", "x"}, {2, 0}, 1);
        FAIL();
    } catch (const PlanError& e) {
        EXPECT_NE(std::string(e.what()).find("'x'"), std::string::npos) << e.what();
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(ConstrainedShuffle, TightButFeasibleConstraintsAreMet) {
    // a b a b a: the only order with max_repeat 1 of three 'a' and two 'b'.
    const std::vector<std::string> levels = {"a", "a", "a", "b", "b"};
    for (uint64_t seed = 0; seed < 20; ++seed) {
        std::vector<std::string> seq;
        for (int i : constrained_shuffle(levels, {1, 0}, seed)) seq.push_back(levels[i]);
        EXPECT_EQ(seq, (std::vector<std::string>{"a", "b", "a", "b", "a"}));
    }
}

TEST(PlanTrials, PracticeFirstThenEveryBlockTrialAndCatchTrialOnce) {
    const Protocol p = builtin_protocol("thesis");
    const TrialPlan plan = plan_trials(p, 12345, 3);
    size_t expected = p.practice.size() + p.catch_trials.size();
    for (const Block& b : p.blocks) expected += b.stimuli.size() * b.repeats;
    ASSERT_EQ(plan.trials.size(), expected);
    for (size_t i = 0; i < p.practice.size(); ++i) {
        EXPECT_TRUE(plan.trials[i].practice);
        EXPECT_EQ(plan.trials[i].stimulus, p.practice[i]);
    }
    std::multiset<std::string> seen, wanted;
    for (const PlannedTrial& t : plan.trials)
        if (!t.practice && !t.is_catch) seen.insert(t.stimulus);
    for (const Block& b : p.blocks) wanted.insert(b.stimuli.begin(), b.stimuli.end());
    EXPECT_EQ(seen, wanted);
    int catches = 0, main_index = 0;
    for (size_t i = 0; i < plan.trials.size(); ++i) {
        const PlannedTrial& t = plan.trials[i];
        EXPECT_EQ(t.position, static_cast<int>(i));
        if (t.is_catch) {
            ++catches;
            EXPECT_GE(t.expected, 1);
            EXPECT_FALSE(t.prompt.empty());
        }
        if (t.practice) continue;
        EXPECT_EQ(t.break_before, main_index > 0 && main_index % p.break_every == 0) << i;
        ++main_index;
    }
    EXPECT_EQ(catches, static_cast<int>(p.catch_trials.size()));
}

TEST(PlanTrials, SeedAndParticipantDetermineTheOrder) {
    const Protocol p = builtin_protocol("thesis");
    auto stimuli = [](const TrialPlan& plan) {
        std::vector<std::string> s;
        for (const PlannedTrial& t : plan.trials) s.push_back(t.stimulus);
        return s;
    };
    EXPECT_EQ(stimuli(plan_trials(p, 5, 1)), stimuli(plan_trials(p, 5, 1)));
    EXPECT_NE(stimuli(plan_trials(p, 5, 1)), stimuli(plan_trials(p, 6, 1)));
    // Two blocks: participants 0 and 1 see them in opposite orders.
    EXPECT_EQ(plan_trials(p, 5, 0).block_order,
              (std::vector<std::string>{"empirical", "contrast_reversal"}));
    EXPECT_EQ(plan_trials(p, 5, 1).block_order,
              (std::vector<std::string>{"contrast_reversal", "empirical"}));
    EXPECT_EQ(plan_trials(p, 5, 1).cell, 1);
}

TEST(PlanTrials, ThesisConstraintsHoldForManySessions) {
    const Protocol p = builtin_protocol("thesis");
    for (uint64_t seed = 0; seed < 200; ++seed) {
        const TrialPlan plan = plan_trials(p, seed, static_cast<int>(seed));
        for (const std::string& block : plan.block_order) {
            std::vector<std::string> seq;
            for (const PlannedTrial& t : plan.trials)
                if (t.block == block) seq.push_back(t.stimulus);
            EXPECT_LE(longest_run(seq), p.randomisation.max_repeat);
            EXPECT_GE(closest_repeat(seq), p.randomisation.min_distance);
        }
    }
}

}  // namespace
}  // namespace lucent::study
