#include "stats/one_way_analysis.h"

namespace lucent::analysis {

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
