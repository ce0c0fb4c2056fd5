#include "analysis/stats/tukey.h"

#include <cmath>
#include <limits>

#include "analysis/stats/descriptives.h"
#include "analysis/stats/studentized_range.h"

namespace lucent::analysis {

TukeyResult tukey_hsd(const OneWayData& data, const AnovaResult& anova,
                      const TukeyOptions& options) {
    TukeyResult r;
    r.alpha = options.alpha;
    const auto groups = nonempty_groups(data);
    const int k = static_cast<int>(groups.size());
    if (k < 2) {
        r.note = "Tukey HSD needs at least two groups";
        return r;
    }
    if (k > kMaxRangeGroups) {
        r.note =
            "Tukey HSD supports at most 200 groups (" + std::to_string(k) + " given)";
        return r;
    }
    if (!anova.ms_within) {
        r.note = "Tukey HSD needs within-group degrees of freedom";
        return r;
    }
    const double msw = *anova.ms_within;
    const double df = anova.df_within;
    r.q_critical = studentized_range_quantile_upper(options.alpha, k, df);

    // HSD threshold per level as the thesis printed it, when every group has n obs.
    bool balanced = true;
    for (const Group* g : groups)
        balanced &= g->values.size() == groups[0]->values.size();
    if (balanced) {
        const double unit =
            std::sqrt(msw / static_cast<double>(groups[0]->values.size()));
        r.hsd_05 = studentized_range_quantile_upper(0.05, k, df) * unit;
        r.hsd_01 = studentized_range_quantile_upper(0.01, k, df) * unit;
    }

    std::vector<double> means;
    const double pivot = pivot_of(data);  // differences of means keep their digits
    for (const Group* g : groups)
        means.push_back(mean_and_squares(g->values, pivot).mean);
    for (int a = 0; a < k; ++a) {
        for (int b = a + 1; b < k; ++b) {
            TukeyPair pair;
            pair.level_a = groups[a]->level;
            pair.level_b = groups[b]->level;
            pair.diff = means[b] - means[a];
            const double se =
                std::sqrt(0.5 * msw *
                          (1.0 / static_cast<double>(groups[a]->values.size()) +
                           1.0 / static_cast<double>(groups[b]->values.size())));
            pair.se = se;
            pair.lower = pair.diff - *r.q_critical * se;
            pair.upper = pair.diff + *r.q_critical * se;
            if (se > 0.0) {
                pair.q = std::fabs(pair.diff) / se;
            } else if (pair.diff != 0.0) {
                pair.q = std::numeric_limits<double>::infinity();
            }  // 0 / 0: q undefined, and so is its p-value
            if (pair.q && options.p_values)
                pair.p_adj = studentized_range_upper(*pair.q, k, df);
            r.pairs.push_back(pair);
        }
    }
    return r;
}

}  // namespace lucent::analysis
