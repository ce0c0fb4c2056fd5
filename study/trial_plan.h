#pragma once
// Trial planning: the full order of a session's trials from (protocol, seed, participant
// number). Pure and GL-free; the store writes the plan before trial 1 so a resumed
// session continues in the same order.
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "study/protocol.h"

namespace lucent::study {

// Randomisation constraints that no order can satisfy, or that the search gave up on.
class PlanError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct PlannedTrial {
    int position = 0;      // 0-based over the whole session, practice first
    std::string block;     // block id; "practice" for practice trials
    std::string stimulus;  // stimulus id
    bool practice = false;
    bool is_catch = false;
    std::string catch_id;  // catch trials: which one, its prompt and expected rating
    std::string prompt;
    int expected = 0;
    int tolerance = 0;
    bool break_before = false;  // show the break screen before this trial
    Task task = Task::rating;   // the block's task (practice ratings: rating)
    // Forced choices: the stimulus ids in screen order (left to right, or first to last
    // when shown in sequence); `stimulus` is shown[0]. Empty for ratings. The answer is
    // one response to the block's question_id, 1 or 2: pair: shown[0] or shown[1] is
    // more X; triad: (shown[0], shown[1]) or (shown[1], shown[2]) differs more;
    // quadruple: (shown[0], shown[1]) or (shown[2], shown[3]) differs more. Catch
    // trials: `expected` is the right answer, 0 when there is none (identical pairs).
    std::vector<std::string> shown;
    // Adjust trials (`stimulus` is the target): the knob value the match starts at,
    // drawn when the plan is made.
    std::optional<double> start_value;
    // Staircase slots: the procedure that runs here, "<standard>/<procedure id>"; the
    // plan holds max_trials slots per procedure in rounds (each round a random order of
    // all procedures). The delta is chosen when the slot comes, from its procedure's
    // answers so far; a slot of a finished procedure is skipped. `shown` holds the
    // standard once per picture and `expected` is the comparison's place (the right
    // answer, 1..pictures).
    std::string staircase;
};

struct TrialPlan {
    int cell = 0;                          // counterbalancing cell (Latin-square row)
    std::vector<std::string> block_order;  // block ids in the order shown
    std::vector<PlannedTrial> trials;
};

// Row `participant_number` (mod the square's size) of a balanced Latin square (Williams
// design) over n conditions: every condition appears once in each position per square,
// and each condition follows every other equally often (2n rows when n is odd).
std::vector<int> latin_square_row(int n, int participant_number);
int latin_square_rows(int n);

// Constraints on the sequence of factor levels of the rated trials. With the factor
// `stimulus` a level is the picture shown (Protocol::picture_key), so stimuli that are
// the same picture under different ids, and a catch trial and its stimulus, count as
// one level.
struct SequenceConstraints {
    int max_repeat = 0;    // longest run of one level allowed (0: unlimited)
    int min_distance = 0;  // two equal levels at least this many positions apart (0: off)
};
bool satisfies(const std::vector<std::string>& levels, const SequenceConstraints& c);

// Throws PlanError naming a level whose count alone makes the constraints impossible.
void check_feasible(const std::vector<std::string>& levels, const SequenceConstraints& c);

// Rejection sampling gives up after this many uniform shuffles (each abandoned at its
// first violation, so an attempt costs a few steps) and counts instead.
inline constexpr int kMaxShuffleAttempts = 2'000'000;
// The exact sampler gives up beyond this many memoised states (block, trials left per
// level, last levels placed): few levels or small blocks stay far below it.
inline constexpr size_t kMaxCountedStates = 500'000;

// Random orders of consecutive blocks, each block's trials (given as levels) permuted
// within the block, such that the blocks' concatenation meets the constraints. Every
// combination of block orders that meets them is equally likely. First by rejection:
// each attempt draws every block uniformly (Fisher-Yates) and is rejected at its first
// violation; after `max_attempts` rejections by exact_block_shuffles. Throws PlanError
// when check_feasible fails for a block, or from exact_block_shuffles.
std::vector<std::vector<int>> constrained_block_shuffles(
    const std::vector<std::vector<std::string>>& blocks, const SequenceConstraints& c,
    std::mt19937_64& rng, int max_attempts = kMaxShuffleAttempts);

// The same distribution by counting: the number of valid completions of a partial order
// is memoised on (block, trials left per level, last levels placed), and each next trial
// is drawn in proportion to the completions after it. Throws PlanError when no order
// meets the constraints, or beyond `max_states` states.
std::vector<std::vector<int>> exact_block_shuffles(
    const std::vector<std::vector<std::string>>& blocks, const SequenceConstraints& c,
    std::mt19937_64& rng, size_t max_states = kMaxCountedStates);

// One block: a uniformly random permutation of `levels` (as indices) among those
// meeting the constraints; the same seed gives the same order.
std::vector<int> constrained_shuffle(const std::vector<std::string>& levels,
                                     const SequenceConstraints& c, uint64_t seed,
                                     int max_attempts = kMaxShuffleAttempts);

// A trial's level for the sequence constraints: a rating's (and an adjustment's
// target's) level of the protocol's factor; a forced choice's unordered set of stimuli
// (the same pair is one level); a staircase slot's own level (its order is its
// procedure's, constraints do not move it).
std::string sequence_level(const PlannedTrial& trial,
                           const std::map<std::string, std::string>& level_of_stimulus);

// Practice trials first, in protocol order; then the blocks in Latin-square order,
// shuffled by constrained_block_shuffles with the protocol's constraints on the whole
// rated sequence (across block boundaries too, catch trials included).
TrialPlan plan_trials(const Protocol& protocol, uint64_t seed, int participant_number);

}  // namespace lucent::study
