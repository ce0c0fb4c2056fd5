#pragma once
// Reading the scaling tests' data sets (tests/analysis/scaling/data, see SOURCE.md).
#include <fstream>
#include <string>
#include <vector>

#include "common/csv.h"

namespace lucent::analysis::testing {

inline std::string scaling_data_path(const std::string& name) {
    return std::string(LUCENT_SOURCE_DIR) + "/tests/analysis/scaling/data/" + name;
}

// The records of a small CSV (header included), one vector of fields each.
inline std::vector<std::vector<std::string>> read_small_csv(const std::string& name) {
    std::ifstream in(scaling_data_path(name));
    std::vector<std::vector<std::string>> records;
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) records.push_back(common::split_csv_line(line));
    return records;
}

}  // namespace lucent::analysis::testing
