#pragma once
// The input of every one-way test: named groups of observations. Values are stored
// relative to `origin` (value = origin + stored): readers subtract a common origin exactly
// in decimal before converting to double, so data such as 1e12 + 0.4 keep their digits
// (NIST SmLs07-09). Every statistic except a mean or median is invariant to the origin.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace lucent::analysis {

struct Group {
    std::string level;
    std::vector<double> values;  // relative to OneWayData::origin
};

struct OneWayData {
    double origin = 0.0;
    std::vector<Group> groups;
};

// A statistic that can be undefined (0/0, too few observations): empty optional. It may
// also be +infinity (e.g. F with zero within-group variance); formatting spells it out.
using Statistic = std::optional<double>;

// Groups that have at least one observation (tests drop empty groups and say so).
std::vector<const Group*> nonempty_groups(const OneWayData& data);
std::size_t total_observations(const OneWayData& data);

}  // namespace lucent::analysis
