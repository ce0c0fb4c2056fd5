#include "analysis/stats/anova.h"

#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <limits>

#include "analysis/stats/descriptives.h"
#include "analysis/stats/summation.h"

namespace lucent::analysis {
namespace {

double f_upper_tail(double f, double df1, double df2) {
    if (std::isinf(f)) return 0.0;
    return boost::math::cdf(boost::math::complement(boost::math::fisher_f(df1, df2), f));
}

}  // namespace

AnovaResult one_way_anova(const OneWayData& data) {
    AnovaResult r;
    const auto groups = nonempty_groups(data);
    r.groups = static_cast<int>(groups.size());
    // Group means and within sums of squares (compensated two-pass per group), then the
    // grand mean weighted by n and the between sum of squares about it.
    // Everything is centred on one observation so that means far from zero keep digits.
    const double pivot = pivot_of(data);
    std::vector<MeanAndSquares> per_group;
    CompensatedSum weighted_means, within;
    for (const Group* group : groups) {
        per_group.push_back(mean_and_squares(group->values, pivot));
        r.observations += group->values.size();
        weighted_means.add(per_group.back().mean *
                           static_cast<double>(group->values.size()));
        within.add(per_group.back().squares);
    }
    if (r.groups < 2) {
        r.note = r.groups == 0 ? "no observations" : "only one group has observations";
        return r;
    }
    const double grand_mean =
        weighted_means.value() / static_cast<double>(r.observations);
    CompensatedSum between;
    for (std::size_t i = 0; i < groups.size(); ++i) {
        const double d = per_group[i].mean - grand_mean;
        between.add(static_cast<double>(groups[i]->values.size()) * d * d);
    }
    r.ss_between = between.value();
    r.ss_within = within.value();
    r.df_between = r.groups - 1;
    r.df_within = static_cast<double>(r.observations) - r.groups;
    r.ms_between = r.ss_between / r.df_between;
    const double ss_total = r.ss_between + r.ss_within;
    if (ss_total > 0.0) r.eta_sq = r.ss_between / ss_total;
    if (r.df_within <= 0.0) {
        r.note = "every group has one observation: no within-group variance";
        return r;
    }
    r.ms_within = r.ss_within / r.df_within;
    if (*r.ms_within > 0.0) {
        r.f = *r.ms_between / *r.ms_within;
        r.omega_sq =
            (r.ss_between - r.df_between * *r.ms_within) / (ss_total + *r.ms_within);
    } else if (*r.ms_between > 0.0) {
        r.f = std::numeric_limits<double>::infinity();
        r.note = "zero within-group variance with different means: F is infinite";
    } else {
        r.note = "all values are identical: F is undefined";
        return r;
    }
    r.p = f_upper_tail(*r.f, r.df_between, r.df_within);
    return r;
}

WelchResult welch_anova(const OneWayData& data) {
    WelchResult r;
    const auto groups = nonempty_groups(data);
    const double k = static_cast<double>(groups.size());
    if (groups.size() < 2) {
        r.note = "Welch's ANOVA needs at least two groups";
        return r;
    }
    // Weights w_i = n_i / s_i^2; the weighted grand mean; then Welch's F and its df.
    std::vector<double> weights, means, sizes;
    CompensatedSum total_weight, weighted_mean;
    const double pivot = pivot_of(data);
    for (const Group* group : groups) {
        const MeanAndSquares ms = mean_and_squares(group->values, pivot);
        const double n = static_cast<double>(group->values.size());
        if (n < 2.0 || ms.squares <= 0.0) {
            r.note =
                "Welch's ANOVA needs two or more observations and a nonzero variance in "
                "every group (level '" +
                group->level + "' has not)";
            return r;
        }
        const double w = n / (ms.squares / (n - 1.0));
        weights.push_back(w);
        means.push_back(ms.mean);
        sizes.push_back(n);
        total_weight.add(w);
        weighted_mean.add(w * ms.mean);
    }
    const double w_sum = total_weight.value();
    const double mean_w = weighted_mean.value() / w_sum;
    CompensatedSum spread, imbalance;
    for (std::size_t i = 0; i < weights.size(); ++i) {
        const double d = means[i] - mean_w;
        spread.add(weights[i] * d * d);
        const double share = 1.0 - weights[i] / w_sum;
        imbalance.add(share * share / (sizes[i] - 1.0));
    }
    const double a = spread.value() / (k - 1.0);
    const double lambda = imbalance.value();
    const double b = 1.0 + 2.0 * (k - 2.0) / (k * k - 1.0) * lambda;
    r.f = a / b;
    r.df1 = k - 1.0;
    r.df2 = (k * k - 1.0) / (3.0 * lambda);
    r.p = f_upper_tail(*r.f, *r.df1, *r.df2);
    return r;
}

}  // namespace lucent::analysis
