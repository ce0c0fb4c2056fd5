#pragma once
// lucent bench stats, the mixed models: `lucent analyze --model lmm|clmm` as a whole
// process against R (lme4::lmer + lmerTest, ordinal::clmm, each with the likelihood-ratio
// or Satterthwaite test of the factor) on the same CSV, per size; wall and CPU time, peak
// memory, and how far apart the two programs' estimates are.
#include <vector>

#include "app/bench_results.h"

namespace lucent::app {

// `sizes`: ratings per study (participants x 60 stimuli x 3 questions, 7-point).
int bench_mixed_models(const std::vector<long>& sizes, int repeat, BenchResults& results);

}  // namespace lucent::app
