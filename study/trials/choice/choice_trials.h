#pragma once
// The forced choices the scaling reads: `pair` (which of two pictures is more X: paired
// comparisons), `triad` and `quadruple` (which of two pairs of an ordered series
// differs more: MLDS). One folder, three kinds: they share the design's keys and plan.
#include <random>
#include <vector>

#include "study/trial_plan.h"

namespace lucent::study {

const TrialKind& pair_trial_kind();
const TrialKind& triad_trial_kind();
const TrialKind& quadruple_trial_kind();

// The trials of a forced-choice block in design order, before shuffling: every pair or
// group of block.design, `repeats` times, its screen order counterbalanced (a pair's two
// orders, a triad forwards and backwards, a quadruple's pairs either first, each equally
// often over the block, odd counts split at random), then the catch trials.
std::vector<PlannedTrial> choice_block_trials(const Block& block, std::mt19937_64& rng);

}  // namespace lucent::study
