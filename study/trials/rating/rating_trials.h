#pragma once
// `rating`: one picture rated on every [[questions]] entry (the thesis's survey); the
// protocol's [[catch_trials]] and [practice] stimuli are ratings.
#include "study/trials/trial_kind.h"

namespace lucent::study {

const TrialKind& rating_trial_kind();

}  // namespace lucent::study
