#pragma once
// Everything the report shows for one (question, factor) pair, computed in one place.
#include "stats/anova.h"
#include "stats/descriptives.h"
#include "stats/kruskal_wallis.h"
#include "stats/tukey.h"

namespace lucent::analysis {

struct OneWayAnalysis {
    std::string question, factor;
    std::vector<Descriptives> descriptives;  // every level, empty ones included
    AnovaResult anova;
    TukeyResult tukey;
    KruskalWallisResult kruskal;
    WelchResult welch;
    std::vector<std::string> empty_levels;  // levels without observations (left out)
    std::size_t missing_ratings = 0;
};

// alpha sets the Tukey intervals' confidence (1 - alpha); descriptives use 95% CIs.
OneWayAnalysis analyze_one_way(const std::string& question, const std::string& factor,
                               const OneWayData& data, double alpha);

}  // namespace lucent::analysis
