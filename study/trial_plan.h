#pragma once
// Trial planning: the full order of a session's trials from (protocol, seed, participant
// number). Pure and GL-free; the store writes the plan before trial 1 so a resumed
// session continues in the same order.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "protocol.h"

namespace lucent::study {

// Randomisation constraints that no order can satisfy, or that the search gave up on.
class PlanError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct PlannedTrial {
    int position = 0;     // 0-based over the whole session, practice first
    std::string block;    // block id; "practice" for practice trials
    std::string stimulus; // stimulus id
    bool practice = false;
    bool is_catch = false;
    std::string catch_id;  // catch trials: which one, its prompt and expected rating
    std::string prompt;
    int expected = 0;
    int tolerance = 0;
    bool break_before = false;  // show the break screen before this trial
};

struct TrialPlan {
    int cell = 0;                         // counterbalancing cell (Latin-square row)
    std::vector<std::string> block_order; // block ids in the order shown
    std::vector<PlannedTrial> trials;
};

// Row `participant_number` (mod the square's size) of a balanced Latin square (Williams
// design) over n conditions: every condition appears once in each position per square,
// and each condition follows every other equally often (2n rows when n is odd).
std::vector<int> latin_square_row(int n, int participant_number);
int latin_square_rows(int n);

// Constraints on the sequence of factor levels of a shuffled block.
struct SequenceConstraints {
    int max_repeat = 0;    // longest run of one level allowed (0: unlimited)
    int min_distance = 0;  // two equal levels at least this many positions apart (0: off)
};
bool satisfies(const std::vector<std::string>& levels, const SequenceConstraints& c);

// A random permutation of `levels` (as indices) meeting the constraints. Throws PlanError
// naming the offending level when the counts make it impossible, or after
// `max_attempts` randomised restarts; never loops forever.
std::vector<int> constrained_shuffle(const std::vector<std::string>& levels,
                                     const SequenceConstraints& c, uint64_t seed,
                                     int max_attempts = 2000);

TrialPlan plan_trials(const Protocol& protocol, uint64_t seed, int participant_number);

}  // namespace lucent::study
