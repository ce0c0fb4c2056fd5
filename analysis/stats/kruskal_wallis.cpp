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
    // Pool (value, group) pairs and sort by value to assign mid-ranks to ties.
    std::vector<std::pair<double, std::size_t>> pooled;
    for (std::size_t g = 0; g < groups.size(); ++g)
        for (double x : groups[g]->values) pooled.emplace_back(x, g);
    std::sort(pooled.begin(), pooled.end());
    const double n = static_cast<double>(pooled.size());
    std::vector<CompensatedSum> rank_sums(groups.size());
    CompensatedSum tie_terms;
    for (std::size_t i = 0; i < pooled.size();) {
        std::size_t j = i;
        while (j < pooled.size() && pooled[j].first == pooled[i].first) ++j;
        const double mid_rank = 0.5 * static_cast<double>(i + 1 + j);  // ranks i+1 .. j
        const double t = static_cast<double>(j - i);
        tie_terms.add(t * t * t - t);
        for (std::size_t m = i; m < j; ++m) rank_sums[pooled[m].second].add(mid_rank);
        i = j;
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
    const double h = (12.0 / (n * (n + 1.0)) * weighted.value() - 3.0 * (n + 1.0)) /
                     tie_correction;
    r.h = std::max(0.0, h);
    r.p = boost::math::cdf(boost::math::complement(boost::math::chi_squared(r.df), *r.h));
    return r;
}

}  // namespace lucent::analysis
