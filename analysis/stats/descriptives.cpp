#include "analysis/stats/descriptives.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>

#include "analysis/stats/summation.h"

namespace lucent::analysis {

std::vector<const Group*> nonempty_groups(const OneWayData& data) {
    std::vector<const Group*> groups;
    for (const Group& group : data.groups)
        if (!group.values.empty()) groups.push_back(&group);
    return groups;
}

std::size_t total_observations(const OneWayData& data) {
    std::size_t n = 0;
    for (const Group& group : data.groups) n += group.values.size();
    return n;
}

double pivot_of(const OneWayData& data) {
    for (const Group& group : data.groups)
        if (!group.values.empty()) return group.values.front();
    return 0.0;
}

MeanAndSquares mean_and_squares(const std::vector<double>& values, double shift) {
    if (values.empty()) return {};
    CompensatedSum sum;
    for (double x : values) sum.add(x - shift);
    const double n = static_cast<double>(values.size());
    const double provisional = sum.value() / n;
    // Second pass about the provisional mean; its residual sum corrects the mean and the
    // squares (the "corrected two-pass algorithm" of Chan, Golub and LeVeque).
    CompensatedSum deviations, squares;
    for (double x : values) {
        const double d = (x - shift) - provisional;
        deviations.add(d);
        squares.add(d * d);
    }
    const double residual = deviations.value();
    return {provisional + residual / n,
            std::max(0.0, squares.value() - residual * residual / n)};
}

Descriptives describe(const Group& group, double origin, double confidence) {
    Descriptives d;
    d.level = group.level;
    d.n = group.values.size();
    if (d.n == 0) return d;
    const double shift = group.values.front();
    const MeanAndSquares ms = mean_and_squares(group.values, shift);
    d.mean = origin + (shift + ms.mean);
    std::vector<double> sorted = group.values;
    const std::size_t half = d.n / 2;
    std::nth_element(sorted.begin(), sorted.begin() + half, sorted.end());
    double median = sorted[half];
    if (d.n % 2 == 0)
        median =
            0.5 * (median + *std::max_element(sorted.begin(), sorted.begin() + half));
    d.median = origin + median;
    if (d.n < 2) return d;
    const double sd = std::sqrt(ms.squares / static_cast<double>(d.n - 1));
    d.sd = sd;
    d.se = sd / std::sqrt(static_cast<double>(d.n));
    const boost::math::students_t t(static_cast<double>(d.n - 1));
    const double half_width = boost::math::quantile(t, 0.5 + 0.5 * confidence) * *d.se;
    d.ci_low = *d.mean - half_width;
    d.ci_high = *d.mean + half_width;
    return d;
}

std::vector<Descriptives> describe_all(const OneWayData& data, double confidence) {
    std::vector<Descriptives> all;
    for (const Group& group : data.groups)
        all.push_back(describe(group, data.origin, confidence));
    return all;
}

}  // namespace lucent::analysis
