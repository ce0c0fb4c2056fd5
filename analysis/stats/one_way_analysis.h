#pragma once
// Everything the report shows for one (question, factor) pair, computed in one place.
#include "analysis/mixed/rating_models.h"
#include "analysis/stats/anova.h"
#include "analysis/stats/descriptives.h"
#include "analysis/stats/kruskal_wallis.h"
#include "analysis/stats/repeated_measures.h"
#include "analysis/stats/tukey.h"

namespace lucent::analysis {

// Which analysis a study's plan names primary: levels rated by different participants
// (between) or every participant rating every level (within, the thesis's survey).
enum class Design { Between, Within };
const char* design_name(Design design);

// The within-subject tests of a pair, on each participant's mean rating per level.
struct WithinSubjectAnalysis {
    bool computed = false;  // false: fewer than two participants rated every level
    std::string note;       // why it was not computed
    int participants = 0;   // complete participants used
    std::vector<std::string> excluded_participants;  // rated some levels, not all
    RepeatedMeasuresAnova anova;
    FriedmanResult friedman;
    std::vector<PairedComparison> paired;
};

WithinSubjectAnalysis analyze_within_subject(const SubjectByLevel& complete,
                                             std::vector<std::string> excluded);

struct OneWayAnalysis {
    std::string question, factor;
    std::vector<Descriptives> descriptives;  // every level, empty ones included
    AnovaResult anova;
    TukeyResult tukey;
    KruskalWallisResult kruskal;
    WelchResult welch;
    std::vector<std::string> empty_levels;  // levels without observations (left out)
    std::size_t missing_ratings = 0;
    WithinSubjectAnalysis within;
    PairModels models;  // the mixed models the request asked for
};

// alpha sets the Tukey intervals' confidence (1 - alpha); descriptives use 95% CIs.
OneWayAnalysis analyze_one_way(const std::string& question, const std::string& factor,
                               const OneWayData& data, double alpha);

}  // namespace lucent::analysis
