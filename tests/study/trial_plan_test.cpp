// Trial planning: Latin-square balance, constrained shuffles over many seeds, and
// impossible constraints reported instead of searched forever.
#include "study/trial_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "tests/study/study_fixtures.h"

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

// Independent picture identity: what is drawn, whatever the stimulus id.
bool same_picture(const Stimulus& a, const Stimulus& b) {
    return a.technique == b.technique && a.mesh == b.mesh &&
           a.parameters == b.parameters && a.image == b.image;
}

// Whether a sequence of trials (indices into `pictures`, a same-picture matrix) keeps
// equal pictures min_distance apart and runs to max_repeat.
bool meets(const std::vector<int>& order, const std::vector<std::vector<bool>>& same,
           const SequenceConstraints& c) {
    for (size_t i = 0; i < order.size(); ++i) {
        for (size_t j = i + 1;
             j < order.size() && static_cast<int>(j - i) < c.min_distance; ++j)
            if (same[order[i]][order[j]]) return false;
        if (c.max_repeat > 0 && i + c.max_repeat < order.size()) {
            bool run = true;
            for (int k = 1; k <= c.max_repeat && run; ++k)
                run = same[order[i]][order[i + k]];
            if (run) return false;
        }
    }
    return true;
}

// Over every order of a block's trials that meets `c` (as meets() judges a whole order),
// how many there are and in how many the trial at each position is a catch trial. Exact,
// by counting prefixes forwards and completions backwards over (trials used, the last
// few trials): the constraints only look that far back, so this equals enumerating all
// n! orders (checked against that on a small block below) in far fewer steps.
std::pair<double, std::vector<double>> catch_position_counts(
    const std::vector<std::vector<bool>>& same, const std::vector<bool>& is_catch,
    const SequenceConstraints& c) {
    const int n = static_cast<int>(same.size());
    const int memory = std::max({c.min_distance - 1, c.max_repeat, 1});
    struct State {
        uint32_t used;
        std::vector<int> last;  // the last `memory` trials, oldest first
        bool operator<(const State& o) const {
            return used != o.used ? used < o.used : last < o.last;
        }
    };
    const auto allowed = [&](const State& s, int next) {
        const int k = static_cast<int>(s.last.size());
        for (int back = 1; back < c.min_distance && back <= k; ++back)
            if (same[s.last[k - back]][next]) return false;
        if (c.max_repeat > 0 && k >= c.max_repeat) {
            const int first = s.last[k - c.max_repeat];
            bool run = same[first][next];
            for (int i = k - c.max_repeat + 1; i < k && run; ++i)
                run = same[first][s.last[i]];
            if (run) return false;
        }
        return true;
    };
    const auto advance = [&](const State& s, int next) {
        State t{s.used | (1u << next), s.last};
        t.last.push_back(next);
        if (static_cast<int>(t.last.size()) > memory) t.last.erase(t.last.begin());
        return t;
    };
    std::vector<std::map<State, double>> prefixes(n + 1), completions(n + 1);
    prefixes[0][State{0, {}}] = 1.0;
    for (int length = 0; length < n; ++length)
        for (const auto& [s, count] : prefixes[length])
            for (int next = 0; next < n; ++next)
                if (!(s.used >> next & 1u) && allowed(s, next))
                    prefixes[length + 1][advance(s, next)] += count;
    for (const auto& [s, count] : prefixes[n]) completions[n][s] = 1.0;
    for (int length = n - 1; length >= 0; --length)
        for (const auto& [s, count] : prefixes[length]) {
            double ways = 0.0;
            for (int next = 0; next < n; ++next)
                if (!(s.used >> next & 1u) && allowed(s, next)) {
                    const auto it = completions[length + 1].find(advance(s, next));
                    if (it != completions[length + 1].end()) ways += it->second;
                }
            if (ways > 0.0) completions[length][s] = ways;
        }
    double valid = 0.0;
    for (const auto& [s, count] : prefixes[n]) valid += count;
    std::vector<double> at(n, 0.0);
    for (int position = 0; position < n; ++position)
        for (const auto& [s, count] : prefixes[position + 1]) {
            const auto it = completions[position + 1].find(s);
            if (it != completions[position + 1].end() && is_catch[s.last.back()])
                at[position] += count * it->second;
        }
    return {valid, at};
}

TEST(PlanTrials, CatchPositionCountsEqualEnumeratingEveryOrder) {
    // Seven trials: pictures A A B B C and catch trials showing A and C.
    const std::vector<int> picture = {0, 0, 1, 1, 2, 0, 2};
    const std::vector<bool> is_catch = {false, false, false, false, false, true, true};
    std::vector<std::vector<bool>> same(7, std::vector<bool>(7));
    for (int i = 0; i < 7; ++i)
        for (int j = 0; j < 7; ++j) same[i][j] = picture[i] == picture[j];
    for (const SequenceConstraints c :
         {SequenceConstraints{1, 3}, SequenceConstraints{1, 2},
          SequenceConstraints{2, 0}}) {
        std::vector<int> order = {0, 1, 2, 3, 4, 5, 6};
        double valid = 0.0;
        std::vector<double> at(7, 0.0);
        do {
            if (!meets(order, same, c)) continue;
            ++valid;
            for (int pos = 0; pos < 7; ++pos) at[pos] += is_catch[order[pos]];
        } while (std::next_permutation(order.begin(), order.end()));
        const auto [counted, counted_at] = catch_position_counts(same, is_catch, c);
        EXPECT_GT(valid, 0.0);
        EXPECT_EQ(counted, valid) << c.max_repeat << " " << c.min_distance;
        EXPECT_EQ(counted_at, at) << c.max_repeat << " " << c.min_distance;
    }
}

// Upper quantile of chi-square with `df` degrees of freedom at P = 0.001
// (Wilson-Hilferty; within about 1% for df >= 3).
double chi_square_999(double df) {
    const double z = 3.0902, h = 2.0 / (9.0 * df);
    return df * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

// Pearson's statistic of observed counts against probabilities; cells expected to be
// empty must be empty. Returns {statistic, degrees of freedom}.
std::pair<double, int> chi_square(const std::vector<double>& observed,
                                  const std::vector<double>& probability) {
    double n = 0.0, statistic = 0.0;
    for (double o : observed) n += o;
    int cells = 0;
    for (size_t i = 0; i < observed.size(); ++i) {
        if (probability[i] == 0.0) {
            EXPECT_EQ(observed[i], 0.0) << "cell " << i << " cannot occur";
            continue;
        }
        const double e = n * probability[i];
        statistic += (observed[i] - e) * (observed[i] - e) / e;
        ++cells;
    }
    return {statistic, cells - 1};
}

TEST(LatinSquare, EveryConditionOncePerPositionAndEachOrderedPairEquallyOften) {
    for (int n = 1; n <= 8; ++n) {
        const int rows = latin_square_rows(n);
        std::vector<std::vector<int>> position_count(n, std::vector<int>(n, 0));
        std::map<std::pair<int, int>, int> adjacent;
        for (int participant = 0; participant < rows; ++participant) {
            const std::vector<int> row = latin_square_row(n, participant);
            ASSERT_EQ(static_cast<int>(row.size()), n);
            EXPECT_EQ(std::set<int>(row.begin(), row.end()).size(),
                      static_cast<size_t>(n));
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
                EXPECT_EQ(count, rows / n)
                    << "n=" << n << " pair " << pair.first << "," << pair.second;
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
            for (int k = 0; k < 2 + (trial + l) % 3; ++k)
                levels.push_back("L" + std::to_string(l));
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
    for (uint64_t seed = 0; seed < 50; ++seed)
        orders.insert(constrained_shuffle(levels, c, seed));
    EXPECT_GT(orders.size(), 40u);
    EXPECT_EQ(constrained_shuffle(levels, c, 99), constrained_shuffle(levels, c, 99));
}

TEST(ConstrainedShuffle, ImpossibleConstraintsAreReportedQuickly) {
    const auto start = std::chrono::steady_clock::now();
    // Four 'a' among six trials cannot avoid adjacent 'a's.
    EXPECT_THROW(constrained_shuffle({"a", "a", "a", "a", "b", "c"}, {1, 0}, 1),
                 PlanError);
    // Three 'a' at distance >= 3 need 7 positions.
    EXPECT_THROW(constrained_shuffle({"a", "a", "a", "b", "c", "d"}, {0, 3}, 1),
                 PlanError);
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

TEST(ConstrainedShuffle, UnmeetableConstraintsWithFeasibleCountsEndInAClearError) {
    // Each of a and b alone fits min_distance 3 in four positions (0 and 3), both cannot.
    try {
        constrained_shuffle({"a", "a", "b", "b"}, {0, 3}, 1);
        FAIL();
    } catch (const PlanError& e) {
        EXPECT_NE(std::string(e.what()).find("relax the constraints"), std::string::npos)
            << e.what();
    }
}

// The thesis protocol's trials per block (stimulus specs, catch flags) in plan order.
struct BlockTrials {
    std::vector<const Stimulus*> stimuli;
    std::vector<bool> is_catch;
};

TEST(PlanTrials, ThesisPlansKeepPicturesApartAndPlaceCatchTrialsUniformly) {
    const Protocol p = builtin_protocol("thesis");
    const SequenceConstraints c{p.randomisation.max_repeat, p.randomisation.min_distance};
    ASSERT_GE(c.min_distance, 2);
    // Expected position of each block's catch trial over all its valid orders, by brute
    // force over every permutation of the block.
    std::map<std::string, std::vector<double>> catch_position_probability;
    std::map<std::string, std::vector<const Stimulus*>> pictures_of_block;
    for (const Block& block : p.blocks) {
        BlockTrials trials;
        for (const std::string& id : block.stimuli) {
            trials.stimuli.push_back(p.find_stimulus(id));
            trials.is_catch.push_back(false);
        }
        for (const CatchTrial& ct : p.catch_trials)
            if (ct.block == block.id) {
                trials.stimuli.push_back(p.find_stimulus(ct.stimulus));
                trials.is_catch.push_back(true);
            }
        const int n = static_cast<int>(trials.stimuli.size());
        std::vector<std::vector<bool>> same(n, std::vector<bool>(n));
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
                same[i][j] = same_picture(*trials.stimuli[i], *trials.stimuli[j]);
        auto [valid, at] = catch_position_counts(same, trials.is_catch, c);
        ASSERT_GT(valid, 0.0) << block.id;
        for (double& a : at) a /= valid;
        catch_position_probability[block.id] = at;
        pictures_of_block[block.id] = trials.stimuli;
    }
    // Blocks share no picture, so the blocks' orders are independent of each other.
    for (const Stimulus* a : pictures_of_block["empirical"])
        for (const Stimulus* b : pictures_of_block["contrast_reversal"])
            ASSERT_FALSE(same_picture(*a, *b)) << a->id << " " << b->id;

    constexpr int kPlans = 20000;
    std::mt19937_64 seeds(2026);
    std::map<std::string, std::vector<double>> catch_at;
    for (const auto& [block, probability] : catch_position_probability)
        catch_at[block].assign(probability.size(), 0.0);
    int same_picture_adjacent = 0, catch_next_to_own_picture = 0, too_close = 0;
    for (int plan_index = 0; plan_index < kPlans; ++plan_index) {
        const TrialPlan plan = plan_trials(p, seeds(), plan_index);
        std::map<std::string, int> block_position;
        for (size_t i = 0; i < plan.trials.size(); ++i) {
            const PlannedTrial& t = plan.trials[i];
            const Stimulus& here = *p.find_stimulus(t.stimulus);
            if (i > 0) {
                const PlannedTrial& before = plan.trials[i - 1];
                const bool same = same_picture(*p.find_stimulus(before.stimulus), here);
                same_picture_adjacent += same;
                catch_next_to_own_picture += same && (t.is_catch || before.is_catch);
            }
            for (size_t back = 1; back < static_cast<size_t>(c.min_distance) && back <= i;
                 ++back)
                too_close +=
                    !plan.trials[i - back].practice && !t.practice &&
                    same_picture(*p.find_stimulus(plan.trials[i - back].stimulus), here);
            if (t.practice) continue;
            const int pos = block_position[t.block]++;
            if (t.is_catch) ++catch_at[t.block][pos];
        }
    }
    EXPECT_EQ(same_picture_adjacent, 0);
    EXPECT_EQ(catch_next_to_own_picture, 0);
    EXPECT_EQ(too_close, 0);
    for (const auto& [block, probability] : catch_position_probability) {
        const auto [statistic, df] = chi_square(catch_at[block], probability);
        ASSERT_GE(df, 1) << block;
        EXPECT_LT(statistic, chi_square_999(std::max(df, 3)))
            << block << ": chi-square " << statistic << " on " << df << " df";
    }
}

// Two blocks sharing a picture (a, a_again and a_third are one picture; the catch trial
// shows b): the constraint spans the block boundary.
const char* kSharedPictureProtocol = R"toml(
[study]
name = "uniform"

[[questions]]
id = "q"
text = "Q"

[[stimuli]]
id = "a"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 18 }

[[stimuli]]
id = "a_again"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 18 }

[[stimuli]]
id = "a_third"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 18 }

[[stimuli]]
id = "b"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 25 }

[[stimuli]]
id = "c"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 30 }

[[stimuli]]
id = "d"
technique = "ward"
mesh = "sphere"
params = { roughness = 0.2 }

[[blocks]]
id = "one"
stimuli = ["a", "b", "a_again"]

[[blocks]]
id = "two"
stimuli = ["c", "a_third", "d"]

[[catch_trials]]
id = "attention"
stimulus = "b"
block = "one"
prompt = "Choose 7"
expected = 7

[randomisation]
factor = "stimulus"
max_repeat = 1
min_distance = 2
counterbalance_blocks = false
)toml";

TEST(PlanTrials, EveryValidOrderOfASmallProtocolIsEquallyLikely) {
    const Protocol p = parse_protocol(kSharedPictureProtocol, "uniform.toml");
    const SequenceConstraints c{1, 2};
    // Trials in protocol order: block one (a, b, a_again, catch on b), block two.
    const std::vector<std::string> ids = {"a", "b", "a_again", "b", "c", "a_third", "d"};
    const std::vector<bool> is_catch = {false, false, false, true, false, false, false};
    auto name = [&](int i) { return ids[i] + (is_catch[i] ? "*" : ""); };
    const int n = static_cast<int>(ids.size());
    std::vector<std::vector<bool>> same(n, std::vector<bool>(n));
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            same[i][j] = same_picture(*p.find_stimulus(ids[i]), *p.find_stimulus(ids[j]));
    // Brute force: every (order of block one, order of block two) meeting the
    // constraints.
    std::map<std::string, int> index_of_order;
    std::vector<int> one = {0, 1, 2, 3};
    do {
        std::vector<int> two = {4, 5, 6};
        do {
            std::vector<int> whole = one;
            whole.insert(whole.end(), two.begin(), two.end());
            if (!meets(whole, same, c)) continue;
            std::string key;
            for (int i : whole) key += name(i) + " ";
            index_of_order.emplace(key, static_cast<int>(index_of_order.size()));
        } while (std::next_permutation(two.begin(), two.end()));
    } while (std::next_permutation(one.begin(), one.end()));
    // By hand: one alternates A/B (8 orders); after a final A, two must not start with A.
    ASSERT_EQ(index_of_order.size(), 40u);

    constexpr int kPlans = 20000;
    const std::vector<double> uniform(index_of_order.size(), 1.0 / index_of_order.size());
    std::vector<double> observed(index_of_order.size(), 0.0);
    auto tally = [&](const std::string& key) {
        const auto it = index_of_order.find(key);
        ASSERT_NE(it, index_of_order.end()) << "order breaks the constraints: " << key;
        ++observed[it->second];
    };
    // The planner (rejection sampling for a protocol this loose).
    std::mt19937_64 seeds(7);
    for (int i = 0; i < kPlans; ++i) {
        std::string key;
        for (const PlannedTrial& t : plan_trials(p, seeds(), 0).trials)
            key += t.stimulus + (t.is_catch ? "*" : "") + " ";
        tally(key);
    }
    auto [statistic, df] = chi_square(observed, uniform);
    EXPECT_LT(statistic, chi_square_999(df))
        << "planner: chi-square " << statistic << " on " << df;
    // The exact sampler (the fallback for rare valid orders) on the same blocks.
    std::vector<std::vector<std::string>> levels(2);
    for (int i = 0; i < n; ++i)
        levels[i < 4 ? 0 : 1].push_back(p.level_of(*p.find_stimulus(ids[i]), "stimulus"));
    std::fill(observed.begin(), observed.end(), 0.0);
    std::mt19937_64 rng(8);
    for (int i = 0; i < kPlans; ++i) {
        const std::vector<std::vector<int>> orders = exact_block_shuffles(levels, c, rng);
        std::string key;
        for (int t : orders[0]) key += name(t) + " ";
        for (int t : orders[1]) key += name(4 + t) + " ";
        tally(key);
    }
    std::tie(statistic, df) = chi_square(observed, uniform);
    EXPECT_LT(statistic, chi_square_999(df))
        << "exact: chi-square " << statistic << " on " << df;
}

TEST(ConstrainedShuffle, RareValidOrdersAreCountedExactlyWhenRejectionGivesUp) {
    // 20 a and 20 b with no repeats: only the 2 x 20! x 20! alternating orders of the
    // 40! are valid (1 in 7e10), beyond rejection sampling.
    std::vector<std::string> levels;
    for (int i = 0; i < 40; ++i) levels.push_back(i < 20 ? "a" : "b");
    const SequenceConstraints c{1, 0};
    auto alternates = [&](const std::vector<int>& order) {
        for (size_t i = 1; i < order.size(); ++i)
            if (levels[order[i]] == levels[order[i - 1]]) return false;
        return true;
    };
    EXPECT_TRUE(alternates(constrained_shuffle(levels, c, 3, /*max_attempts=*/1000)));
    // Uniform over the valid orders: the first trial starts half the orders, and trial 0
    // (an 'a') is equally likely in each of the 20 positions its level can hold.
    constexpr int kOrders = 4000;
    std::mt19937_64 rng(11);
    int a_first = 0;
    std::vector<double> slot_of_trial_0(20, 0.0);
    for (int i = 0; i < kOrders; ++i) {
        const std::vector<int> order = exact_block_shuffles({levels}, c, rng).front();
        ASSERT_TRUE(alternates(order));
        a_first += levels[order[0]] == "a";
        const int at =
            static_cast<int>(std::find(order.begin(), order.end(), 0) - order.begin());
        ++slot_of_trial_0[at / 2];
    }
    EXPECT_NEAR(a_first, kOrders / 2, 4 * std::sqrt(kOrders / 4.0));
    const auto [statistic, df] =
        chi_square(slot_of_trial_0, std::vector<double>(20, 1.0 / 20));
    EXPECT_LT(statistic, chi_square_999(df))
        << "chi-square " << statistic << " on " << df;
    // And an impossible case that passes the count check is now a definite answer.
    try {
        exact_block_shuffles({{"a", "a", "b", "b"}}, {0, 3}, rng);
        FAIL();
    } catch (const PlanError& e) {
        EXPECT_NE(std::string(e.what()).find("no order of the 4 trials meets"),
                  std::string::npos)
            << e.what();
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
