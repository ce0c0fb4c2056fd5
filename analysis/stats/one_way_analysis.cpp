#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

const char* design_name(Design design) {
    return design == Design::Within ? "within" : "between";
}

WithinSubjectAnalysis analyze_within_subject(const SubjectByLevel& complete,
                                             std::vector<std::string> excluded) {
    WithinSubjectAnalysis w;
    w.participants = static_cast<int>(complete.rows());
    w.excluded_participants = std::move(excluded);
    if (complete.rows() < 2 || complete.columns() < 2) {
        w.note = complete.columns() < 2
                     ? "one level: nothing to compare within participants"
                     : "not a within-subject layout: " + std::to_string(complete.rows()) +
                           " participant(s) rated every level (at least 2 needed)";
        return w;
    }
    w.computed = true;
    w.anova = repeated_measures_anova(complete);
    w.friedman = friedman_test(complete);
    w.paired = paired_t_tests_holm(complete);
    return w;
}

OneWayAnalysis analyze_one_way(const std::string& question, const std::string& factor,
                               const OneWayData& data, double alpha) {
    OneWayAnalysis a;
    a.question = question;
    a.factor = factor;
    a.descriptives = describe_all(data, 0.95);
    for (const Group& g : data.groups)
        if (g.values.empty()) a.empty_levels.push_back(g.level);
    a.anova = one_way_anova(data);
    a.tukey = tukey_hsd(data, a.anova, {alpha, true});
    a.kruskal = kruskal_wallis(data);
    a.welch = welch_anova(data);
    return a;
}

}  // namespace lucent::analysis
