#pragma once
// Splits the long table into one-way layouts: one per (question, factor) pair, the
// factor's levels as groups.
#include "analysis/data/long_table.h"
#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

struct FactorData {
    std::string question, factor;
    OneWayData data;
    std::size_t missing_ratings = 0;  // rows with an empty rating
};

// Pairs in order of first appearance; an empty filter keeps everything. Levels are in
// numeric order when every level of the factor is a number, else in order of appearance.
// A level whose rows all lack a rating becomes an empty group.
std::vector<FactorData> split_by_question_and_factor(
    const LongTable& table, const std::string& question_filter = "",
    const std::string& factor_filter = "");

}  // namespace lucent::analysis
