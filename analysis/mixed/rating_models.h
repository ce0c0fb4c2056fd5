#pragma once
// The mixed models of one (question, factor) pair of a rating study, as analysts now
// publish them (Judd, Westfall and Kenny 2012): participants and stimuli both sampled, so
// both get random intercepts, and the ordinal model for Likert ratings.
//
//   clmm: rating ~ level + (1 | participant) + (1 | stimulus), logit link, flexible
//         thresholds (R's ordinal::clmm); the factor tested by a likelihood ratio.
//   lmm:  the same linear model (R's lme4::lmer, REML), the factor tested by
//         Satterthwaite's F (lmerTest's anova) and by a likelihood ratio (ML refits).
//
// A term the data cannot carry is left out and said so in words: one participant (no
// participant variance), one stimulus per level (stimulus and level confounded), a
// single stimulus. Nothing is ever NaN: what is undefined is empty with a note.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/stats/one_way_data.h"

namespace lucent::analysis {

enum class RatingModel { anova, lmm, clmm };
const char* rating_model_name(RatingModel model);

// Which analyses a report runs (`--model anova,clmm`) and which one leads it.
struct ModelChoice {
    bool anova = true, lmm = false, clmm = true;
    // lmm: random slopes for the level within participant, (1 + level | participant),
    // where the design identifies them (every participant rated every level at least
    // twice, and more participants than the slopes' covariance has parameters).
    bool random_slopes = false;
    RatingModel primary = RatingModel::anova;
    std::string primary_source;  // who chose `primary`, for the report
    bool runs(RatingModel model) const;
};
// A comma-separated subset of anova,lmm,clmm; throws InputError naming a bad entry.
// The primary stays `primary` when it runs, else the first listed.
ModelChoice parse_model_list(const std::string& list, RatingModel primary);
// "anova", "lmm" or "clmm"; throws InputError naming `what` otherwise.
RatingModel parse_rating_model(const std::string& text, const std::string& what);

// One level's effect against the reference level (log odds for clmm, rating points for
// lmm) with its 95% interval.
struct LevelEffect {
    std::string level;
    double estimate = 0.0, standard_error = 0.0;
    Statistic low, high;  // empty when not estimable
    bool estimable = true;
};

struct RatingModelFit {
    RatingModel model = RatingModel::clmm;
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

struct PairModels {
    std::optional<RatingModelFit> lmm, clmm;
};

// Called before each model `choice` asks for (fit: nullptr) and after it (fit: the
// result, fitted or not), lmm first: progress on long runs.
using ModelFitHook = std::function<void(RatingModel model, const RatingModelFit* fit)>;

// Fits the models `choice` asks for to the ratings of (question, factor) at `levels`
// (in that order; levels without ratings are left out).
PairModels fit_pair_models(const LongTable& table, const std::string& question,
                           const std::string& factor,
                           const std::vector<std::string>& levels,
                           const ModelChoice& choice, const ModelFitHook& on_fit = {});

}  // namespace lucent::analysis
