#include "analysis/stats/kruskal_wallis.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <numeric>

#include "analysis/stats/summation.h"

namespace lucent::analysis {

KruskalWallisResult kruskal_wallis(const OneWayData& data) {
    KruskalWallisResult r;
    const auto groups = nonempty_groups(data);
    if (groups.size() < 2) {
        r.note = "Kruskal-Wallis needs at least two groups";
        return r;
    }
    // A value's mid-rank depends only on the value: find the distinct values and how
    // often each occurs in each group, then every group's rank sum is a sum over the
    // distinct values. Ratings are whole numbers in a short range: counted straight into
    // a histogram (no search, no sort of all n). Other data: the pooled values are
    // sorted once and each group's values found by binary search.
    std::size_t total = 0;
    for (const Group* g : groups) total += g->values.size();
    std::vector<double> distinct;
    std::vector<std::size_t> counts;
    std::vector<std::vector<std::size_t>> in_group(groups.size());
    double lowest = groups[0]->values[0], highest = lowest;
    bool whole = true;
    for (const Group* g : groups)
        for (double x : g->values) {
            lowest = std::min(lowest, x);
            highest = std::max(highest, x);
            whole &= x == std::nearbyint(x);
        }
    constexpr double kHistogramSpan = 4096;
    if (whole && std::isfinite(lowest) && std::isfinite(highest) &&
        highest - lowest < kHistogramSpan &&
        (highest - lowest + 1) * static_cast<double>(groups.size()) <= 1 << 20) {
        const std::size_t span = static_cast<std::size_t>(highest - lowest) + 1;
        std::vector<std::vector<std::size_t>> histogram(
            groups.size(), std::vector<std::size_t>(span, 0));
        for (std::size_t g = 0; g < groups.size(); ++g)
            for (double x : groups[g]->values)
                ++histogram[g][static_cast<std::size_t>(x - lowest)];
        for (std::size_t v = 0; v < span; ++v) {
            std::size_t count = 0;
            for (const auto& h : histogram) count += h[v];
            if (count == 0) continue;
            distinct.push_back(lowest + static_cast<double>(v));
            counts.push_back(count);
            for (std::size_t g = 0; g < groups.size(); ++g)
                in_group[g].push_back(histogram[g][v]);
        }
    } else {
        std::vector<double> pooled;
        pooled.reserve(total);
        for (const Group* g : groups)
            pooled.insert(pooled.end(), g->values.begin(), g->values.end());
        std::sort(pooled.begin(), pooled.end());
        for (std::size_t i = 0; i < pooled.size();) {
            std::size_t j = i;
            while (j < pooled.size() && pooled[j] == pooled[i]) ++j;
            distinct.push_back(pooled[i]);
            counts.push_back(j - i);
            i = j;
        }
        for (std::size_t g = 0; g < groups.size(); ++g) {
            in_group[g].assign(distinct.size(), 0);
            for (double x : groups[g]->values)
                ++in_group[g][std::lower_bound(distinct.begin(), distinct.end(), x) -
                              distinct.begin()];
        }
    }
    const double n = static_cast<double>(total);
    std::vector<double> mid_ranks(distinct.size());
    CompensatedSum tie_terms;
    std::size_t below = 0;
    for (std::size_t d = 0; d < distinct.size(); ++d) {
        mid_ranks[d] =
            0.5 * static_cast<double>(below + 1 + below +
                                      counts[d]);  // ranks below+1 .. below+count
        const double t = static_cast<double>(counts[d]);
        tie_terms.add(t * t * t - t);
        below += counts[d];
    }
    std::vector<CompensatedSum> rank_sums(groups.size());
    for (std::size_t g = 0; g < groups.size(); ++g)
        for (std::size_t d = 0; d < distinct.size(); ++d)
            if (in_group[g][d] > 0)
                rank_sums[g].add(mid_ranks[d] * static_cast<double>(in_group[g][d]));
    const double tie_correction = 1.0 - tie_terms.value() / (n * n * n - n);
    r.df = static_cast<double>(groups.size() - 1);
    if (!(tie_correction > 0.0)) {
        r.note = "all values are tied: H is undefined";
        return r;
    }
    CompensatedSum weighted;
    for (std::size_t g = 0; g < groups.size(); ++g) {
        const double rank_sum = rank_sums[g].value();
        weighted.add(rank_sum * rank_sum / static_cast<double>(groups[g]->values.size()));
    }
    const double h =
        (12.0 / (n * (n + 1.0)) * weighted.value() - 3.0 * (n + 1.0)) / tie_correction;
    r.h = std::max(0.0, h);
    r.p = boost::math::cdf(boost::math::complement(boost::math::chi_squared(r.df), *r.h));
    return r;
}

}  // namespace lucent::analysis
