#pragma once
// `adjust`: a live match object beside a target picture, whose knob the participant
// turns until the two look alike; one answer, the confirmation of the final value.
#include <random>
#include <vector>

#include "study/trial_plan.h"

namespace lucent::study {

const TrialKind& adjust_trial_kind();

// An adjust block's trials in design order, before shuffling: each target `repeats`
// times, each with its start value (adjust_start_value).
std::vector<PlannedTrial> adjust_block_trials(const Block& block, std::mt19937_64& rng);
// Where an adjust trial's match starts: block.start's number, range_min ("min"),
// range_max ("max"), or ("random") uniform over the range on the block's scale (its
// logarithm for "log"), at a point of the browser's series (adjust_series_values: one of
// Block::series_steps evenly spaced points), so both start from the same values.
double adjust_start_value(const Block& block, std::mt19937_64& rng);

}  // namespace lucent::study
