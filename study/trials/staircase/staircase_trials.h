#pragma once
// `staircase`: a forced choice between a standard and the standard with a knob changed
// by a delta that an adaptive procedure (up/down or QUEST) chooses trial by trial.
#include <random>
#include <vector>

#include "study/trial_plan.h"

namespace lucent::study {

const TrialKind& staircase_trial_kind();

// A staircase block's slots in their final order (not shuffled again): for each
// standard and [[blocks.staircases]] entry a procedure "<standard>/<id>" with max_trials
// slots, laid out in rounds, each round a random order of the procedures with slots
// left; each procedure's comparison place balanced over its slots (every place equally
// often, a remainder at random).
std::vector<PlannedTrial> staircase_block_trials(const Block& block,
                                                 std::mt19937_64& rng);

}  // namespace lucent::study
