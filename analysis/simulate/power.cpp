#include "analysis/simulate/power.h"

#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/non_central_f.hpp>
#include <cmath>

#include "analysis/data/long_table.h"
#include "analysis/simulate/normal_source.h"
#include "analysis/stats/anova.h"
#include "analysis/stats/tukey.h"

namespace lucent::analysis {
namespace {

bool rejects(const Statistic& p, double alpha) { return p && *p < alpha; }

double response(const PowerSpec& spec, double latent) {
    if (!spec.likert) return latent;
    return std::clamp(std::round(latent), 1.0, 7.0);
}

}  // namespace

PowerEstimate power_estimate(long hits, int runs) {
    const double p = static_cast<double>(hits) / runs;
    return {p, std::sqrt(p * (1.0 - p) / runs)};
}

void check_power_spec(const PowerSpec& spec) {
    if (spec.participants < 2)
        throw InputError("--participants must be at least 2, got " +
                         std::to_string(spec.participants));
    if (spec.level_means.size() < 2 || spec.level_means.size() > 200)
        throw InputError("--means needs 2 to 200 levels, got " +
                         std::to_string(spec.level_means.size()));
    for (double m : spec.level_means)
        if (!std::isfinite(m)) throw InputError("--means must be finite numbers");
    if (!(spec.participant_sd >= 0.0 && std::isfinite(spec.participant_sd)))
        throw InputError("--participant-sd must be a finite number >= 0");
    if (!(spec.residual_sd > 0.0 && std::isfinite(spec.residual_sd)))
        throw InputError("--residual-sd must be a finite number > 0");
    if (!(spec.alpha > 0.0 && spec.alpha < 1.0))
        throw InputError("--alpha must lie strictly between 0 and 1");
    if (spec.simulations < 10 || spec.simulations > 10000000)
        throw InputError("--simulations must lie in [10, 10000000], got " +
                         std::to_string(spec.simulations));
}

std::optional<double> closed_form_power(const PowerSpec& spec) {
    if (spec.likert) return std::nullopt;
    const double k = static_cast<double>(spec.level_means.size());
    const double n = spec.participants;
    double grand = 0.0;
    for (double m : spec.level_means) grand += m;
    grand /= k;
    double spread = 0.0;
    for (double m : spec.level_means) spread += (m - grand) * (m - grand);
    const bool within = spec.design == Design::Within;
    const double variance = within ? spec.residual_sd * spec.residual_sd
                                   : spec.participant_sd * spec.participant_sd +
                                         spec.residual_sd * spec.residual_sd;
    const double df1 = k - 1.0;
    const double df2 = within ? (n - 1.0) * (k - 1.0) : k * (n - 1.0);
    const double lambda = n * spread / variance;
    const double critical = boost::math::quantile(
        boost::math::complement(boost::math::fisher_f(df1, df2), spec.alpha));
    if (lambda == 0.0) return spec.alpha;
    return boost::math::cdf(
        boost::math::complement(boost::math::non_central_f(df1, df2, lambda), critical));
}

PowerResult estimate_power(const PowerSpec& spec) {
    check_power_spec(spec);
    PowerResult result;
    result.spec = spec;
    result.closed_form = closed_form_power(spec);
    const std::size_t k = spec.level_means.size();
    const std::size_t n = static_cast<std::size_t>(spec.participants);
    const bool within = spec.design == Design::Within;
    result.pairwise_test = within ? "paired t-tests, Holm" : "Tukey HSD";
    for (std::size_t a = 0; a < k; ++a)
        for (std::size_t b = a + 1; b < k; ++b)
            result.pairs.push_back({std::to_string(a + 1), std::to_string(b + 1), {}});

    NormalSource normal(spec.seed);
    long one_way_hits = 0, rm_hits = 0, rm_gg_hits = 0, any_pair_hits = 0;
    std::vector<long> pair_hits(result.pairs.size(), 0);
    OneWayData groups;
    SubjectByLevel matrix;
    for (std::size_t j = 0; j < k; ++j) {
        groups.groups.push_back({std::to_string(j + 1), std::vector<double>(n)});
        matrix.levels.push_back(std::to_string(j + 1));
    }
    matrix.participants.resize(n);
    matrix.values.resize(n * k);
    for (int run = 0; run < spec.simulations; ++run) {
        for (std::size_t i = 0; i < n; ++i) {
            const double shared = within ? spec.participant_sd * normal.next() : 0.0;
            for (std::size_t j = 0; j < k; ++j) {
                const double own = within ? shared : spec.participant_sd * normal.next();
                const double y = response(
                    spec, spec.level_means[j] + own + spec.residual_sd * normal.next());
                groups.groups[j].values[i] = y;
                matrix.values[i * k + j] = y;
            }
        }
        const AnovaResult anova = one_way_anova(groups);
        one_way_hits += rejects(anova.p, spec.alpha);
        std::vector<bool> significant(result.pairs.size(), false);
        if (within) {
            const RepeatedMeasuresAnova rm = repeated_measures_anova(matrix);
            rm_hits += rejects(rm.p, spec.alpha);
            rm_gg_hits += rejects(rm.p_gg ? rm.p_gg : rm.p, spec.alpha);
            const std::vector<PairedComparison> paired = paired_t_tests_holm(matrix);
            for (std::size_t c = 0; c < paired.size(); ++c)
                significant[c] = rejects(paired[c].p_holm, spec.alpha);
        } else {
            // Simultaneous intervals at 1 - alpha exclude 0 exactly when p adj < alpha.
            const TukeyResult tukey = tukey_hsd(groups, anova, {spec.alpha, false});
            for (std::size_t c = 0; c < tukey.pairs.size() && c < significant.size();
                 ++c) {
                const TukeyPair& p = tukey.pairs[c];
                significant[c] = p.lower && p.upper && (*p.lower > 0.0 || *p.upper < 0.0);
            }
        }
        bool any = false;
        for (std::size_t c = 0; c < significant.size(); ++c) {
            pair_hits[c] += significant[c];
            any = any || significant[c];
        }
        any_pair_hits += any;
    }
    result.one_way_anova = power_estimate(one_way_hits, spec.simulations);
    if (within) {
        result.rm_anova = power_estimate(rm_hits, spec.simulations);
        result.rm_anova_gg = power_estimate(rm_gg_hits, spec.simulations);
    }
    result.any_pair = power_estimate(any_pair_hits, spec.simulations);
    for (std::size_t c = 0; c < result.pairs.size(); ++c)
        result.pairs[c].estimate = power_estimate(pair_hits[c], spec.simulations);
    return result;
}

SampleSize smallest_sample(PowerSpec spec, double target, int max_participants) {
    if (!(target > 0.0 && target < 1.0))
        throw InputError("--target must lie strictly between 0 and 1");
    if (max_participants < 2) throw InputError("--max-participants must be at least 2");
    SampleSize size;
    auto power_at = [&](int participants) {
        spec.participants = participants;
        ++size.evaluations;
        return estimate_power(spec);
    };
    PowerResult high = power_at(max_participants);
    if (high.primary().power < target) {
        size.at = std::move(high);
        return size;
    }
    int lo = 1,
        hi = max_participants;  // power(lo) < target (by convention), power(hi) >= target
    while (hi - lo > 1) {
        const int mid = lo + (hi - lo) / 2;
        PowerResult at_mid = power_at(std::max(2, mid));
        if (at_mid.primary().power >= target) {
            hi = mid;
            high = std::move(at_mid);
        } else {
            lo = mid;
        }
    }
    size.participants = std::max(2, hi);
    size.at = std::move(high);
    return size;
}

}  // namespace lucent::analysis
