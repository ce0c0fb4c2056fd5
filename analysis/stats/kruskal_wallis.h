#pragma once
// Kruskal-Wallis rank test with the correction for ties:
//   H = [12 / (N (N+1)) sum R_i^2 / n_i - 3 (N+1)] / [1 - sum (t^3 - t) / (N^3 - N)],
// chi-square with k - 1 df. Ratings on a 7-point scale are mostly ties; the correction
// matters.
#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

struct KruskalWallisResult {
    Statistic h;
    double df = 0;
    Statistic p;
    std::string note;
};

KruskalWallisResult kruskal_wallis(const OneWayData& data);

}  // namespace lucent::analysis
