// Trial planning: practice in protocol order, then blocks in Latin-square order, each
// block shuffled under the protocol's constraints, with catch trials mixed in.
#include "study/trial_plan.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "common/portable_random.h"
#include "study/web_series.h"

namespace lucent::study {
namespace {

using common::portable_shuffle;
using common::uniform_below;
using common::uniform_unit;

// Whether `level` may follow the placed prefix.
bool may_place(const std::vector<const std::string*>& placed, const std::string& level,
               const SequenceConstraints& c) {
    const int n = static_cast<int>(placed.size());
    if (c.min_distance > 1)
        for (int back = 1; back < c.min_distance && back <= n; ++back)
            if (*placed[n - back] == level) return false;
    if (c.max_repeat > 0 && n >= c.max_repeat) {
        bool run = true;
        for (int back = 1; back <= c.max_repeat && run; ++back)
            run = *placed[n - back] == level;
        if (run) return false;
    }
    return true;
}

// Exact sampling by counting (the fallback when rejection is too rare): the number of
// valid completions of a partial order depends only on the block, the trials left per
// level and the last few levels placed, so it is memoised on that state, and each next
// level is drawn with probability (trials left of it) x (completions after it) / (all
// completions), then one of its trials uniformly: every valid order is equally likely
// (up to the rounding of long double counts).
class OrderCounter {
public:
    OrderCounter(const std::vector<std::vector<std::string>>& blocks,
                 const SequenceConstraints& c, size_t max_states)
        : c_(c), max_states_(max_states) {
        std::map<std::string, int> ids;
        for (const auto& block : blocks) {
            std::vector<int>& levels = blocks_.emplace_back();
            for (const std::string& l : block)
                levels.push_back(
                    ids.emplace(l, static_cast<int>(ids.size())).first->second);
        }
        levels_ = static_cast<int>(ids.size());
        window_ = std::max(c.min_distance > 1 ? c.min_distance - 1 : 0,
                           std::max(c.max_repeat, 0));
    }

    struct State {
        size_t block = 0;
        std::vector<int> left;  // trials left per level in this block
        std::vector<int>
            recent;  // the last window_ levels placed, oldest first; -1: none
    };
    State start() const {
        State s{0, counts(0), std::vector<int>(window_, -1)};
        while (s.block + 1 < blocks_.size() && empty(s.left)) s.left = counts(++s.block);
        return s;
    }
    // Whether `level` may be placed after `recent`.
    bool allowed(const std::vector<int>& recent, int level) const {
        const int n = static_cast<int>(recent.size());
        if (c_.min_distance > 1)
            for (int back = 1; back < c_.min_distance; ++back)
                if (recent[n - back] == level) return false;
        if (c_.max_repeat > 0) {
            bool run = true;
            for (int back = 1; back <= c_.max_repeat && run; ++back)
                run = recent[n - back] == level;
            if (run) return false;
        }
        return true;
    }
    // `s` after placing a trial of `level`; moves to the next block when one is done.
    State place(const State& s, int level) const {
        State next = s;
        --next.left[level];
        if (window_ > 0) {
            next.recent.erase(next.recent.begin());
            next.recent.push_back(level);
        }
        while (next.block + 1 < blocks_.size() && empty(next.left))
            next.left = counts(++next.block);
        return next;
    }
    bool done(const State& s) const {
        return s.block + 1 >= blocks_.size() && empty(s.left);
    }
    // Valid completions of `s`.
    long double completions(const State& s) {
        if (done(s)) return 1.0L;
        std::string key(reinterpret_cast<const char*>(&s.block), sizeof s.block);
        key.append(reinterpret_cast<const char*>(s.left.data()),
                   s.left.size() * sizeof(int));
        key.append(reinterpret_cast<const char*>(s.recent.data()),
                   s.recent.size() * sizeof(int));
        if (const auto it = memo_.find(key); it != memo_.end()) return it->second;
        long double total = 0.0L;
        for (int level = 0; level < levels_; ++level)
            if (s.left[level] > 0 && allowed(s.recent, level))
                total += s.left[level] * completions(place(s, level));
        if (memo_.size() >= max_states_)
            throw PlanError("randomisation: too many distinct states (over " +
                            std::to_string(max_states_) +
                            ") to count the valid orders exactly; relax the constraints");
        memo_.emplace(std::move(key), total);
        return total;
    }
    const std::vector<int>& block_levels(size_t b) const { return blocks_[b]; }
    size_t blocks() const { return blocks_.size(); }
    int levels() const { return levels_; }

private:
    std::vector<int> counts(size_t b) const {
        std::vector<int> left(levels_, 0);
        for (int l : blocks_[b]) ++left[l];
        return left;
    }
    static bool empty(const std::vector<int>& left) {
        return std::all_of(left.begin(), left.end(), [](int n) { return n == 0; });
    }

    SequenceConstraints c_;
    size_t max_states_;
    std::vector<std::vector<int>> blocks_;
    int levels_ = 0;
    int window_ = 0;
    std::unordered_map<std::string, long double> memo_;
};

}  // namespace

// Necessary conditions on level counts; a violation means no order exists.
void check_feasible(const std::vector<std::string>& levels,
                    const SequenceConstraints& c) {
    std::map<std::string, int> counts;
    for (const std::string& l : levels) ++counts[l];
    const long n = static_cast<long>(levels.size());
    for (const auto& [level, count] : counts) {
        // Runs of at most max_repeat, separated by at least one other trial.
        if (c.max_repeat > 0 && count > static_cast<long>(c.max_repeat) * (n - count + 1))
            throw PlanError("randomisation: level '" + level + "' occurs " +
                            std::to_string(count) + " times in " + std::to_string(n) +
                            " trials; no order keeps runs to max_repeat = " +
                            std::to_string(c.max_repeat));
        if (c.min_distance > 1 && static_cast<long>(count - 1) * c.min_distance + 1 > n)
            throw PlanError("randomisation: level '" + level + "' occurs " +
                            std::to_string(count) + " times in " + std::to_string(n) +
                            " trials; they cannot be min_distance = " +
                            std::to_string(c.min_distance) + " apart");
    }
}

int latin_square_rows(int n) { return n % 2 == 0 ? n : 2 * n; }

std::vector<int> latin_square_row(int n, int participant_number) {
    if (n <= 0) return {};
    const int rows = latin_square_rows(n);
    const int row = ((participant_number % rows) + rows) % rows;
    // Williams first row 0, 1, n-1, 2, n-2, ...; row r adds r; odd n adds the reverses.
    std::vector<int> order(n);
    const int shift = row % n;
    for (int j = 0; j < n; ++j) {
        int base = (j % 2 == 1) ? (j + 1) / 2 : (n - j / 2) % n;
        if (j == 0) base = 0;
        order[j] = (base + shift) % n;
    }
    if (row >= n) std::reverse(order.begin(), order.end());
    return order;
}

bool satisfies(const std::vector<std::string>& levels, const SequenceConstraints& c) {
    std::vector<const std::string*> placed;
    for (const std::string& l : levels) {
        if (!may_place(placed, l, c)) return false;
        placed.push_back(&l);
    }
    return true;
}

std::vector<std::vector<int>> constrained_block_shuffles(
    const std::vector<std::vector<std::string>>& blocks, const SequenceConstraints& c,
    std::mt19937_64& rng, int max_attempts) {
    size_t total = 0;
    for (const std::vector<std::string>& levels : blocks) {
        check_feasible(levels, c);
        total += levels.size();
    }
    std::vector<std::vector<int>> orders(blocks.size());
    std::vector<const std::string*> placed;
    placed.reserve(total);
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
        // Fisher-Yates per block, checking each trial as it is placed: stopping at the
        // first violation rejects the same shuffles as checking them whole, so the
        // accepted ones stay uniform over the orders that meet the constraints.
        placed.clear();
        bool valid = true;
        for (size_t b = 0; b < blocks.size() && valid; ++b) {
            std::vector<int>& order = orders[b];
            const int n = static_cast<int>(blocks[b].size());
            order.resize(n);
            for (int i = 0; i < n; ++i) order[i] = i;
            for (int i = 0; i < n && valid; ++i) {
                std::swap(order[i], order[i + uniform_below(rng, n - i)]);
                const std::string& level = blocks[b][order[i]];
                valid = may_place(placed, level, c);
                placed.push_back(&level);
            }
        }
        if (valid) return orders;
    }
    // Valid orders are rare among all orders (or absent): count them instead.
    return exact_block_shuffles(blocks, c, rng);
}

std::vector<std::vector<int>> exact_block_shuffles(
    const std::vector<std::vector<std::string>>& blocks, const SequenceConstraints& c,
    std::mt19937_64& rng, size_t max_states) {
    OrderCounter counter(blocks, c, max_states);
    OrderCounter::State state = counter.start();
    size_t trials = 0;
    for (const auto& b : blocks) trials += b.size();
    if (counter.completions(state) <= 0.0L)
        throw PlanError("randomisation: no order of the " + std::to_string(trials) +
                        " trials meets max_repeat = " + std::to_string(c.max_repeat) +
                        " and min_distance = " + std::to_string(c.min_distance) +
                        "; relax the constraints");
    std::vector<std::vector<int>> orders(blocks.size());
    std::vector<std::vector<int>> unplaced;  // the current block's trials, per level
    size_t block = blocks.size();            // none yet
    while (!counter.done(state)) {
        if (state.block != block) {
            block = state.block;
            unplaced.assign(counter.levels(), {});
            for (int i = 0; i < static_cast<int>(blocks[block].size()); ++i)
                unplaced[counter.block_levels(block)[i]].push_back(i);
        }
        long double u =
            static_cast<long double>(rng() >> 11) * 0x1p-53L * counter.completions(state);
        int chosen = -1;
        for (int level = 0; level < counter.levels(); ++level) {
            if (state.left[level] == 0 || !counter.allowed(state.recent, level)) continue;
            const long double weight =
                state.left[level] * counter.completions(counter.place(state, level));
            if (weight <= 0.0L) continue;
            chosen = level;  // the last possible level takes any rounding remainder
            if (u < weight) break;
            u -= weight;
        }
        std::vector<int>& pool = unplaced[chosen];
        const size_t k = uniform_below(rng, pool.size());
        orders[block].push_back(pool[k]);
        pool.erase(pool.begin() + static_cast<long>(k));
        state = counter.place(state, chosen);
    }
    return orders;
}

std::vector<int> constrained_shuffle(const std::vector<std::string>& levels,
                                     const SequenceConstraints& c, uint64_t seed,
                                     int max_attempts) {
    std::mt19937_64 rng(seed);
    return constrained_block_shuffles({levels}, c, rng, max_attempts).front();
}

std::string sequence_level(const PlannedTrial& trial,
                           const std::map<std::string, std::string>& level_of_stimulus) {
    return trial.task->sequence_level(trial, level_of_stimulus);
}

std::string TrialKind::sequence_level(
    const PlannedTrial& trial,
    const std::map<std::string, std::string>& level_of_stimulus) const {
    return level_of_stimulus.at(trial.stimulus);
}

TrialPlan plan_trials(const Protocol& protocol, uint64_t seed, int participant_number) {
    TrialPlan plan;
    for (const std::string& id : protocol.practice) {
        PlannedTrial t;
        t.block = "practice";
        t.stimulus = id;
        t.practice = true;
        plan.trials.push_back(t);
    }
    // Practice of a block's own task (the forced choices'): the first trials of its
    // design in a random order of its own (a stream apart from the main order's, so
    // adding practice does not change the main trials).
    std::mt19937_64 practice_rng(seed ^ 0x9e3779b97f4a7c15ULL);
    for (const Block& block : protocol.blocks) {
        if (block.practice == 0) continue;
        std::vector<PlannedTrial> pool =
            block.task->plan_block(protocol, block, practice_rng);
        pool.erase(std::remove_if(pool.begin(), pool.end(),
                                  [](const PlannedTrial& t) { return t.is_catch; }),
                   pool.end());
        portable_shuffle(pool, practice_rng);
        for (int i = 0; i < block.practice && !pool.empty(); ++i) {
            PlannedTrial t = pool[i % pool.size()];
            t.practice = true;
            plan.trials.push_back(t);
        }
    }

    const int n_blocks = static_cast<int>(protocol.blocks.size());
    std::vector<int> order(n_blocks);
    for (int i = 0; i < n_blocks; ++i) order[i] = i;
    if (protocol.randomisation.counterbalance_blocks) {
        plan.cell = ((participant_number % latin_square_rows(n_blocks)) +
                     latin_square_rows(n_blocks)) %
                    latin_square_rows(n_blocks);
        order = latin_square_row(n_blocks, participant_number);
    }

    const Randomisation& rz = protocol.randomisation;
    std::vector<std::vector<PlannedTrial>> block_trials;
    for (int b : order) {
        const Block& block = protocol.blocks[b];
        plan.block_order.push_back(block.id);
        std::vector<PlannedTrial>& trials = block_trials.emplace_back();
        // Its own stream per block, so the design of one block does not depend on the
        // order of the others.
        std::mt19937_64 design_rng(seed + 0x632be59bd9b4e019ULL * (b + 1));
        trials = block.task->plan_block(protocol, block, design_rng);
        // A slot's level names its place in the block: unique, so the constraints never
        // hold a staircase's rounds back.
        for (size_t i = 0; i < trials.size(); ++i)
            trials[i].position = static_cast<int>(i);
    }
    if (rz.shuffle) {
        const SequenceConstraints constraints{rz.max_repeat, rz.min_distance};
        const std::map<std::string, std::string> level_of = protocol.levels_of(rz.factor);
        std::vector<std::vector<std::string>> levels(block_trials.size());
        for (size_t b = 0; b < block_trials.size(); ++b) {
            for (const PlannedTrial& t : block_trials[b])
                levels[b].push_back(sequence_level(t, level_of));
            try {
                check_feasible(levels[b], constraints);
            } catch (const PlanError& e) {
                throw PlanError(protocol.source + ": block '" + plan.block_order[b] +
                                "': " + e.what());
            }
        }
        std::mt19937_64 rng(seed);
        std::vector<std::vector<int>> orders;
        try {
            orders = constrained_block_shuffles(levels, constraints, rng);
        } catch (const PlanError& e) {
            throw PlanError(protocol.source + ": " + e.what());
        }
        for (size_t b = 0; b < block_trials.size(); ++b) {
            // A staircase block keeps its rounds (its slots' levels are unique, so any
            // order of them meets the constraints).
            if (!protocol.find_block(plan.block_order[b])->task->shuffled()) continue;
            std::vector<PlannedTrial> shuffled;
            for (int i : orders[b]) shuffled.push_back(block_trials[b][i]);
            block_trials[b] = std::move(shuffled);
        }
    }
    int main_index = 0;
    for (std::vector<PlannedTrial>& trials : block_trials)
        for (PlannedTrial& t : trials) {
            t.break_before = protocol.break_every > 0 && main_index > 0 &&
                             main_index % protocol.break_every == 0;
            ++main_index;
            plan.trials.push_back(std::move(t));
        }
    for (int i = 0; i < static_cast<int>(plan.trials.size()); ++i)
        plan.trials[i].position = i;
    return plan;
}

}  // namespace lucent::study
