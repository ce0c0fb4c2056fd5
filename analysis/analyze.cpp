#include "analyze.h"

#include "data/grouping.h"
#include "data/subject_matrix.h"

namespace lucent::analysis {

AnalysisResult analyze_table(const LongTable& table, const AnalysisRequest& request) {
    const auto pairs =
        split_by_question_and_factor(table, request.question, request.factor);
    if (pairs.empty())
        throw InputError(
            std::string("no ratings") +
            (request.question.empty() ? "" : " for question '" + request.question + "'") +
            (request.factor.empty() ? "" : " for factor '" + request.factor + "'"));
    AnalysisResult result;
    std::vector<OneWayAnalysis>& analyses = result.pairs;
    for (const FactorData& pair : pairs) {
        if (request.on_pair)
            request.on_pair(pair.question, pair.factor, pair.data.groups.size());
        analyses.push_back(
            analyze_one_way(pair.question, pair.factor, pair.data, request.alpha));
        analyses.back().missing_ratings = pair.missing_ratings;
        std::vector<std::string> levels;
        for (const Group& g : pair.data.groups) levels.push_back(g.level);
        SubjectMatrix matrix = subject_by_level(table, pair.question, pair.factor, levels);
        analyses.back().within = analyze_within_subject(
            matrix.complete, std::move(matrix.incomplete_participants));
    }
    bool all_within = true;
    for (const OneWayAnalysis& a : analyses) all_within = all_within && a.within.computed;
    result.primary = request.primary.value_or(all_within ? Design::Within : Design::Between);
    return result;
}

}  // namespace lucent::analysis
