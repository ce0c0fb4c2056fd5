#pragma once
// The mixed models of one (question, factor) pair of a rating study, as analysts now
// publish them (Judd, Westfall and Kenny 2012): participants and stimuli both sampled, so
// both get random intercepts. Each model is one file of analysis/models/ and one line of
// its registry (clmm, the ordinal model for Likert ratings; lmm, its linear cousin);
// this file holds what they share: the pair's frame, the random terms its data carry,
// the fit's record, and the loop that fits every model asked for.
//
// A term the data cannot carry is left out and said so in words: one participant (no
// participant variance), one stimulus per level (stimulus and level confounded), a
// single stimulus. Nothing is ever NaN: what is undefined is empty with a note.
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/mixed/model_frame.h"
#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

// "anova": the one-way tests (analysis/stats), always known; any other name is a
// registered mixed model (analysis/models/rating_model.h).
inline constexpr const char* kOneWayTests = "anova";

// Which analyses a report runs (`--model anova,clmm`) and which one leads it.
struct ModelChoice {
    bool anova = true;
    std::vector<std::string> mixed = {"clmm"};  // registered models, in registry order
    // lmm: random slopes for the level within participant, (1 + level | participant),
    // where the design identifies them (every participant rated every level at least
    // twice, and more participants than the slopes' covariance has parameters).
    bool random_slopes = false;
    std::string primary = kOneWayTests;
    std::string primary_source;  // who chose `primary`, for the report
    bool runs(const std::string& model) const;
};
// A comma-separated subset of anova and the registered models; throws InputError naming
// a bad entry. The primary stays `primary` when it runs, else the first listed.
ModelChoice parse_model_list(const std::string& list, const std::string& primary);
// "anova" or a registered model's name, returned; throws InputError naming `what`
// otherwise.
std::string parse_rating_model(const std::string& text, const std::string& what);

// One level's effect against the reference level (log odds for clmm, rating points for
// lmm) with its 95% interval.
struct LevelEffect {
    std::string level;
    double estimate = 0.0, standard_error = 0.0;
    Statistic low, high;  // empty when not estimable
    bool estimable = true;
};

struct RatingModelFit {
    std::string model;  // its registered name
    std::string
        formula;  // as R would be called, e.g. "rating ~ level + (1 | participant)"
    bool fitted = false;
    int observations = 0, participants = 0, stimuli = 0;
    // The factor's test: clmm the likelihood ratio; lmm Satterthwaite's F (statistic,
    // df numerator, df denominator) and the likelihood ratio in lr_*.
    Statistic statistic, df, den_df, p;
    Statistic lr_chi_square, lr_df, lr_p;
    std::string reference_level;
    std::vector<LevelEffect> effects;
    // Standard deviations: participant, stimulus (when in the model), residual (lmm).
    std::vector<std::pair<std::string, double>> random_sds;
    Statistic log_likelihood;
    std::vector<std::string> notes;  // one sentence per hard case met
    // clmm: the rating categories, and per level (in `levels` order) the predicted
    // probability of each (random effects at zero: a typical participant and stimulus)
    // and the observed proportion.
    std::vector<std::string> categories, levels;
    std::vector<std::vector<double>> predicted, observed;
};

// The fits of one pair, in registry order.
struct PairModels {
    std::vector<RatingModelFit> fits;
    const RatingModelFit* of(std::string_view model) const;  // nullptr: not fitted
};

// The pair's ratings as a model frame: rating, level, participant, stimulus.
struct PairFrame {
    mixed::DataFrame frame;
    std::vector<double> ratings;
    std::vector<std::string> levels;  // with ratings, in the requested order
    std::set<std::string> participants, stimuli;
};

// The random intercepts the data can carry, each left out with a sentence when not.
struct RandomStructure {
    bool participant = true, stimulus = true;
    std::vector<std::string> notes;
};

// What a model's fit starts from (analysis/models/): its formula, counts and notes.
RatingModelFit empty_fit(const std::string& model, const PairFrame& pair,
                         const RandomStructure& structure);
// "rating ~ level + (1 | participant) + (1 | stimulus)", the terms the data carry.
std::string formula(const RandomStructure& structure);
// `value` when finite; empty otherwise (nothing NaN reaches a report).
Statistic finite(double value);

// Called before each model `choice` asks for (fit: nullptr) and after it (fit: the
// result, fitted or not), in registry order: progress on long runs.
using ModelFitHook =
    std::function<void(const std::string& model, const RatingModelFit* fit)>;

// Fits the models `choice` asks for to the ratings of (question, factor) at `levels`
// (in that order; levels without ratings are left out).
PairModels fit_pair_models(const LongTable& table, const std::string& question,
                           const std::string& factor,
                           const std::vector<std::string>& levels,
                           const ModelChoice& choice, const ModelFitHook& on_fit = {});

}  // namespace lucent::analysis
