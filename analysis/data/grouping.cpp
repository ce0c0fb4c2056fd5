#include "analysis/data/grouping.h"

#include <algorithm>
#include <map>

#include "common/number_text.h"

namespace lucent::analysis {

std::vector<FactorData> split_by_question_and_factor(const LongTable& table,
                                                     const std::string& question_filter,
                                                     const std::string& factor_filter) {
    std::vector<FactorData> pairs;
    std::map<std::pair<std::string, std::string>, std::size_t> pair_index;
    std::vector<std::map<std::string, std::size_t>> level_index;
    // Rows mostly come in runs of one (question, factor, level): the previous row's
    // indices are checked first, and the maps only consulted when the run changes.
    const RatingRow* previous = nullptr;
    std::size_t pair_at = 0, group_at = 0;
    for (const RatingRow& row : table.rows) {
        if (!question_filter.empty() && row.question != question_filter) continue;
        if (!factor_filter.empty() && row.factor != factor_filter) continue;
        const bool same_pair = previous && row.question == previous->question &&
                               row.factor == previous->factor;
        if (!same_pair) {
            auto [it, inserted] =
                pair_index.emplace(std::pair{row.question, row.factor}, pairs.size());
            if (inserted) {
                pairs.push_back({row.question, row.factor, {table.origin, {}}, 0});
                level_index.emplace_back();
            }
            pair_at = it->second;
        }
        FactorData& pair = pairs[pair_at];
        if (!same_pair || row.level != previous->level) {
            auto [level, new_level] =
                level_index[pair_at].emplace(row.level, pair.data.groups.size());
            if (new_level) pair.data.groups.push_back({row.level, {}});
            group_at = level->second;
        }
        previous = &row;
        if (row.rating)
            pair.data.groups[group_at].values.push_back(*row.rating);
        else
            ++pair.missing_ratings;
    }
    for (FactorData& pair : pairs) {
        auto& groups = pair.data.groups;
        const bool numeric =
            std::all_of(groups.begin(), groups.end(), [](const Group& g) {
                return common::parse_finite_number(g.level).has_value();
            });
        if (numeric)
            std::stable_sort(groups.begin(), groups.end(),
                             [](const Group& a, const Group& b) {
                                 return *common::parse_finite_number(a.level) <
                                        *common::parse_finite_number(b.level);
                             });
    }
    return pairs;
}

}  // namespace lucent::analysis
