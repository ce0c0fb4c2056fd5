#pragma once
// The figure analysts expect for an ordinal model: per level, the predicted probability
// of each rating stacked to 1 (a wide bar), beside the observed proportions (a narrow
// bar), the categories in a sequential palette from the lowest rating to the highest.
#include <string>
#include <vector>

namespace lucent::analysis {

// predicted[level][category], observed[level][category]; each row sums to 1 (or 0 for a
// level without ratings, drawn empty).
std::string ordinal_probability_svg(const std::string& title, const std::string& factor,
                                    const std::vector<std::string>& levels,
                                    const std::vector<std::string>& categories,
                                    const std::vector<std::vector<double>>& predicted,
                                    const std::vector<std::vector<double>>& observed);

}  // namespace lucent::analysis
