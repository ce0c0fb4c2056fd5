#pragma once
// Classical one-way ANOVA with effect sizes, and Welch's heteroscedastic ANOVA.
#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

struct AnovaResult {
    int groups = 0;  // groups with at least one observation
    std::size_t observations = 0;
    double df_between = 0, df_within = 0;
    double ss_between = 0, ss_within = 0;
    Statistic ms_between, ms_within;  // undefined when their df is 0
    Statistic f;                      // +inf: zero within variance, different means
    Statistic p;                      // P(F' > F), Boost's complement; 0 when F is +inf
    Statistic eta_sq, omega_sq;
    std::string note;  // why something is undefined, or "" when all is
};

AnovaResult one_way_anova(const OneWayData& data);

struct WelchResult {
    Statistic f, df1, df2, p;
    std::string note;
};

// Welch (1951): needs >= 2 groups, each with >= 2 observations and a nonzero variance.
WelchResult welch_anova(const OneWayData& data);

}  // namespace lucent::analysis
