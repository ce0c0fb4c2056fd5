#include "analyze.h"

#include "data/grouping.h"

namespace lucent::analysis {

std::vector<OneWayAnalysis> analyze_table(const LongTable& table,
                                          const AnalysisRequest& request) {
    const auto pairs =
        split_by_question_and_factor(table, request.question, request.factor);
    if (pairs.empty())
        throw InputError(
            std::string("no ratings") +
            (request.question.empty() ? "" : " for question '" + request.question + "'") +
            (request.factor.empty() ? "" : " for factor '" + request.factor + "'"));
    std::vector<OneWayAnalysis> analyses;
    for (const FactorData& pair : pairs) {
        if (request.on_pair)
            request.on_pair(pair.question, pair.factor, pair.data.groups.size());
        analyses.push_back(
            analyze_one_way(pair.question, pair.factor, pair.data, request.alpha));
        analyses.back().missing_ratings = pair.missing_ratings;
    }
    return analyses;
}

}  // namespace lucent::analysis
