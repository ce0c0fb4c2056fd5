#pragma once
// Tukey's HSD with the Tukey-Kramer adjustment for unequal group sizes, in R's TukeyHSD
// conventions: diff = mean(b) - mean(a), q = |diff| / se with
// se = sqrt(MS_within / 2 * (1/n_a + 1/n_b)), p_adj = P(Q(k, df_within) > q), and the
// simultaneous interval diff -/+ q_crit * se at confidence 1 - alpha.
#include "analysis/stats/anova.h"

namespace lucent::analysis {

struct TukeyPair {
    std::string level_a, level_b;
    double diff = 0.0;
    Statistic se, q, p_adj, lower, upper;
};

struct TukeyResult {
    double alpha = 0.05;
    Statistic q_critical;      // q with P(Q > q) = alpha
    Statistic hsd_05, hsd_01;  // the thesis's HSD[.05], HSD[.01]; balanced groups only
    std::vector<TukeyPair> pairs;
    std::string note;
};

struct TukeyOptions {
    double alpha = 0.05;
    // Each p-value costs a few microseconds (after a ~10 ms table per k); a caller that
    // only needs the simultaneous intervals (the null simulations) can skip them.
    bool p_values = true;
};

// Pairs of groups with observations, in group order; `anova` must come from the same
// data.
TukeyResult tukey_hsd(const OneWayData& data, const AnovaResult& anova,
                      const TukeyOptions& options = {});

}  // namespace lucent::analysis
