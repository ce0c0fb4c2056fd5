#pragma once
// A rating model, as the registry knows it: its name (`--model NAME`, a protocol's
// [analysis] primary_model), how the report speaks of it, how it fits one (question,
// factor) pair and what it shows. A model is one file of this folder and one line of
// registry.cpp; a test may register one for its lifetime (RatingModelRegistration).
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/mixed/rating_models.h"
#include "analysis/report/document.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

struct CrossedSample;

struct RatingModelSpec {
    std::string name;  // "clmm"
    // The report's words: what ran ("ordinal mixed model (clmm) per (question, factor)
    // ...; "), what leads when it is primary ("ordinal mixed model (clmm)"), the
    // summary's test column ("likelihood ratio (chi-square)").
    std::string ran, title, test;
    std::string help;  // one line for --model's help
    // The pair's fit; `choice` carries the options (random_slopes).
    std::function<RatingModelFit(const PairFrame&, const RandomStructure&,
                                 const ModelChoice&)>
        fit;
    // The pair's section of the report (a heading of level 3 first).
    std::function<std::vector<Block>(const OneWayAnalysis&, const RatingModelFit&)>
        blocks;
    // `lucent power --model NAME`: the level's p-value in one simulated crossed study
    // (analysis/simulate/crossed_power.h), or empty where the model has no power
    // simulation; and whether the simulated responses are rounded to the 1..7 scale.
    std::function<Statistic(const CrossedSample&)> crossed_p;
    bool rounds_to_scale = false;
};

// Every registered model, in registry order: the order they are fitted, reported and
// listed.
const std::vector<const RatingModelSpec*>& rating_models();
const RatingModelSpec* find_rating_model(std::string_view name);
// "anova, clmm, lmm": every name --model accepts.
std::string rating_model_names();
// "anova (the one-way tests), clmm (ordinal mixed model), ...": each with its help.
std::string rating_model_help();

// Adds a model to the registry while it lives (tests); a name taken is a logic_error.
class RatingModelRegistration {
public:
    explicit RatingModelRegistration(const RatingModelSpec& model);
    ~RatingModelRegistration();
    RatingModelRegistration(const RatingModelRegistration&) = delete;
    RatingModelRegistration& operator=(const RatingModelRegistration&) = delete;

private:
    const RatingModelSpec* model_;
};

}  // namespace lucent::analysis
