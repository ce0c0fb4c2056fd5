#pragma once
// Per-group descriptive statistics: n, mean, SD, SE, median and the t-based confidence
// interval of the mean.
#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

struct Descriptives {
    std::string level;
    std::size_t n = 0;
    Statistic mean, sd, se, median;  // sd, se need n >= 2; mean, median need n >= 1
    Statistic ci_low, ci_high;       // mean -/+ t(1 - (1-confidence)/2, n-1) * se
};

// Mean and sum of squared deviations by compensated two-pass summation over (x - shift).
// A shift near the data (any observation) keeps every digit of values far from zero.
struct MeanAndSquares {
    double mean = 0.0;  // relative to the shift
    double squares = 0.0;
};
MeanAndSquares mean_and_squares(const std::vector<double>& values, double shift = 0.0);

// A value from the data to centre on (the first observation), 0 when there is none.
double pivot_of(const OneWayData& data);

Descriptives describe(const Group& group, double origin, double confidence = 0.95);
std::vector<Descriptives> describe_all(const OneWayData& data, double confidence = 0.95);

}  // namespace lucent::analysis
