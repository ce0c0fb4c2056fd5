#include "stats/kruskal_wallis.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <numeric>

#include "stats/summation.h"

namespace lucent::analysis {

KruskalWallisResult kruskal_wallis(const OneWayData& data) {
    KruskalWallisResult r;
    const auto groups = nonempty_groups(data);
    if (groups.size() < 2) {
        r.note = "Kruskal-Wallis needs at least two groups";
        return r;
    }
    // A value's mid-rank depends only on the value: find the distinct values and how
    // often each occurs, then give every observation its value's mid-rank. A rating
    // scale has a handful of distinct values (counted in a small sorted table, no sort
    // of all n); otherwise the pooled values are sorted once.
    std::size_t total = 0;
    for (const Group* g : groups) total += g->values.size();
    std::vector<double> distinct;
    std::vector<std::size_t> counts;
    constexpr std::size_t kFewDistinct = 64;
    bool few = true;
    for (std::size_t g = 0; g < groups.size() && few; ++g)
        for (double x : groups[g]->values) {
            const auto at = std::lower_bound(distinct.begin(), distinct.end(), x);
            if (at != distinct.end() && *at == x) {
                ++counts[at - distinct.begin()];
                continue;
            }
            if (distinct.size() == kFewDistinct) {
                few = false;
                break;
            }
            counts.insert(counts.begin() + (at - distinct.begin()), 1);
            distinct.insert(at, x);
        }
    if (!few) {
        std::vector<double> pooled;
        pooled.reserve(total);
        for (const Group* g : groups)
            pooled.insert(pooled.end(), g->values.begin(), g->values.end());
        std::sort(pooled.begin(), pooled.end());
        distinct.clear();
        counts.clear();
        for (std::size_t i = 0; i < pooled.size();) {
            std::size_t j = i;
            while (j < pooled.size() && pooled[j] == pooled[i]) ++j;
            distinct.push_back(pooled[i]);
            counts.push_back(j - i);
            i = j;
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
    for (std::size_t g = 0; g < groups.size(); ++g) {
        // Within a group, add each distinct value's mid-rank times its count there.
        std::vector<std::size_t> in_group(distinct.size(), 0);
        for (double x : groups[g]->values)
            ++in_group[std::lower_bound(distinct.begin(), distinct.end(), x) -
                       distinct.begin()];
        for (std::size_t d = 0; d < distinct.size(); ++d)
            if (in_group[d] > 0)
                rank_sums[g].add(mid_ranks[d] * static_cast<double>(in_group[d]));
    }
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
