// Trial planning: practice in protocol order, then blocks in Latin-square order, each
// block shuffled under the protocol's constraints, with catch trials mixed in.
#include "trial_plan.h"

#include <algorithm>
#include <map>
#include <random>

namespace lucent::study {
namespace {

// Uniform integer in [0, n) by rejection, identical on every standard library.
uint64_t uniform_below(std::mt19937_64& rng, uint64_t n) {
    const uint64_t limit = UINT64_MAX - UINT64_MAX % n;
    uint64_t x;
    do x = rng(); while (x >= limit);
    return x % n;
}

// Necessary conditions on level counts; a violation means no order exists.
void check_feasible(const std::vector<std::string>& levels, const SequenceConstraints& c) {
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

// Whether `level` may follow the placed prefix.
bool may_place(const std::vector<const std::string*>& placed, const std::string& level,
               const SequenceConstraints& c) {
    const int n = static_cast<int>(placed.size());
    if (c.min_distance > 1)
        for (int back = 1; back < c.min_distance && back <= n; ++back)
            if (*placed[n - back] == level) return false;
    if (c.max_repeat > 0 && n >= c.max_repeat) {
        bool run = true;
        for (int back = 1; back <= c.max_repeat && run; ++back) run = *placed[n - back] == level;
        if (run) return false;
    }
    return true;
}

}  // namespace

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

std::vector<int> constrained_shuffle(const std::vector<std::string>& levels,
                                     const SequenceConstraints& c, uint64_t seed,
                                     int max_attempts) {
    check_feasible(levels, c);
    std::mt19937_64 rng(seed);
    const int n = static_cast<int>(levels.size());
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
        // Randomised greedy: place a random allowed trial; start over when stuck.
        std::vector<int> remaining(n), order;
        for (int i = 0; i < n; ++i) remaining[i] = i;
        std::vector<const std::string*> placed;
        while (!remaining.empty()) {
            std::vector<int> allowed;
            for (int k = 0; k < static_cast<int>(remaining.size()); ++k)
                if (may_place(placed, levels[remaining[k]], c)) allowed.push_back(k);
            if (allowed.empty()) break;
            const int k = allowed[uniform_below(rng, allowed.size())];
            order.push_back(remaining[k]);
            placed.push_back(&levels[remaining[k]]);
            remaining.erase(remaining.begin() + k);
        }
        if (static_cast<int>(order.size()) == n) return order;
    }
    throw PlanError("randomisation: no order of " + std::to_string(n) +
                    " trials met max_repeat = " + std::to_string(c.max_repeat) +
                    " and min_distance = " + std::to_string(c.min_distance) + " in " +
                    std::to_string(max_attempts) + " attempts; relax the constraints");
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

    const int n_blocks = static_cast<int>(protocol.blocks.size());
    std::vector<int> order(n_blocks);
    for (int i = 0; i < n_blocks; ++i) order[i] = i;
    if (protocol.randomisation.counterbalance_blocks) {
        plan.cell = ((participant_number % latin_square_rows(n_blocks)) +
                     latin_square_rows(n_blocks)) % latin_square_rows(n_blocks);
        order = latin_square_row(n_blocks, participant_number);
    }

    const Randomisation& rz = protocol.randomisation;
    const SequenceConstraints constraints{rz.max_repeat, rz.min_distance};
    std::mt19937_64 seeds(seed);
    int main_index = 0;
    for (int b : order) {
        const Block& block = protocol.blocks[b];
        plan.block_order.push_back(block.id);
        std::vector<PlannedTrial> trials;
        for (int r = 0; r < block.repeats; ++r)
            for (const std::string& id : block.stimuli) {
                PlannedTrial t;
                t.block = block.id;
                t.stimulus = id;
                trials.push_back(t);
            }
        for (const CatchTrial& c : protocol.catch_trials) {
            if (c.block != block.id) continue;
            PlannedTrial t;
            t.block = block.id;
            t.stimulus = c.stimulus;
            t.is_catch = true;
            t.catch_id = c.id;
            t.prompt = c.prompt;
            t.expected = c.expected;
            t.tolerance = c.tolerance;
            trials.push_back(t);
        }
        const uint64_t block_seed = seeds();  // drawn for every block: stable per block
        if (rz.shuffle) {
            std::vector<std::string> levels;
            for (const PlannedTrial& t : trials)
                levels.push_back(protocol.level_of(*protocol.find_stimulus(t.stimulus), rz.factor));
            std::vector<int> perm;
            try {
                perm = constrained_shuffle(levels, constraints, block_seed);
            } catch (const PlanError& e) {
                throw PlanError(protocol.source + ": block '" + block.id + "': " + e.what());
            }
            std::vector<PlannedTrial> shuffled;
            for (int i : perm) shuffled.push_back(trials[i]);
            trials = std::move(shuffled);
        }
        for (PlannedTrial& t : trials) {
            t.break_before = protocol.break_every > 0 && main_index > 0 &&
                             main_index % protocol.break_every == 0;
            ++main_index;
            plan.trials.push_back(std::move(t));
        }
    }
    for (int i = 0; i < static_cast<int>(plan.trials.size()); ++i) plan.trials[i].position = i;
    return plan;
}

}  // namespace lucent::study
