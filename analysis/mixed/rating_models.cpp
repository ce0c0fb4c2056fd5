#include "analysis/mixed/rating_models.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <future>
#include <map>
#include <set>

#include "analysis/mixed/clmm.h"
#include "analysis/mixed/lmm.h"
#include "common/number_text.h"

namespace lucent::analysis {
namespace {

using mixed::DataFrame;
using mixed::FactorColumn;

constexpr double kNormal975 = 1.959963984540054;  // qnorm(0.975)
// Ordinal models for ratings on at most this many integer points; beyond it a rating is
// a number (a slider), not a category.
constexpr int kMostCategories = 11;

// The pair's ratings as a model frame: rating, level, participant, stimulus.
struct PairFrame {
    DataFrame frame;
    std::vector<double> ratings;
    std::vector<std::string> levels;  // with ratings, in the requested order
    std::set<std::string> participants, stimuli;
};

PairFrame pair_frame(const LongTable& table, const std::string& question,
                     const std::string& factor, const std::vector<std::string>& levels) {
    PairFrame pair;
    std::vector<std::string> rating_text, level, participant, stimulus;
    std::set<std::string> wanted(levels.begin(), levels.end()), seen;
    for (const RatingRow& row : table.rows) {
        if (row.question != question || row.factor != factor || !row.rating) continue;
        if (!wanted.count(row.level.str())) continue;
        const double value = table.origin + *row.rating;
        pair.ratings.push_back(value);
        rating_text.push_back(common::shortest_text(value));
        level.push_back(row.level.str());
        participant.push_back(row.participant.str());
        stimulus.push_back(row.stimulus.str());
        seen.insert(row.level.str());
        pair.participants.insert(row.participant.str());
        pair.stimuli.insert(row.stimulus.str());
    }
    for (const auto& l : levels)
        if (seen.count(l)) pair.levels.push_back(l);
    pair.frame.set("rating", std::move(rating_text));
    pair.frame.set("level", std::move(level));
    pair.frame.set("participant", std::move(participant));
    pair.frame.set("stimulus", std::move(stimulus));
    return pair;
}

// The random intercepts the data can carry, each left out with a sentence when not.
struct RandomStructure {
    bool participant = true, stimulus = true;
    std::vector<std::string> notes;
};

RandomStructure random_structure(const PairFrame& pair) {
    RandomStructure structure;
    if (pair.participants.size() < 2) {
        structure.participant = false;
        structure.notes.push_back(
            "One participant: there is no spread between participants to estimate, so "
            "the participant term is left out.");
    }
    std::map<std::string, std::set<std::string>> stimuli_of_level;
    const auto& level = pair.frame.text("level");
    const auto& stimulus = pair.frame.text("stimulus");
    for (std::size_t i = 0; i < level.size(); ++i)
        stimuli_of_level[level[i]].insert(stimulus[i]);
    const bool one_per_level =
        std::all_of(stimuli_of_level.begin(), stimuli_of_level.end(),
                    [](const auto& entry) { return entry.second.size() == 1; });
    if (pair.stimuli.size() < 2) {
        structure.stimulus = false;
        structure.notes.push_back("One stimulus: the stimulus term is left out.");
    } else if (one_per_level) {
        structure.stimulus = false;
        structure.notes.push_back(
            "One stimulus per level: stimulus and level are confounded, so the stimulus "
            "term is left out and the level effects include the pictures' own "
            "differences (show several pictures per level to separate them).");
    }
    return structure;
}

std::string formula(const RandomStructure& structure) {
    std::string text = "rating ~ level";
    if (structure.participant) text += " + (1 | participant)";
    if (structure.stimulus) text += " + (1 | stimulus)";
    return text;
}

RatingModelFit empty_fit(RatingModel model, const PairFrame& pair,
                         const RandomStructure& structure) {
    RatingModelFit fit;
    fit.model = model;
    fit.formula = formula(structure);
    fit.observations = int(pair.ratings.size());
    fit.participants = int(pair.participants.size());
    fit.stimuli = int(pair.stimuli.size());
    fit.levels = pair.levels;
    fit.reference_level = pair.levels.empty() ? "" : pair.levels.front();
    fit.notes = structure.notes;
    return fit;
}

Statistic finite(double value) {
    return std::isfinite(value) ? Statistic(value) : std::nullopt;
}

// Whether (1 + level | participant) is identified, and if not, why not.
std::string why_slopes_not_identified(const PairFrame& pair) {
    std::map<std::string, std::map<std::string, int>> ratings_of;
    const auto& participant = pair.frame.text("participant");
    const auto& level = pair.frame.text("level");
    for (std::size_t i = 0; i < participant.size(); ++i)
        ++ratings_of[participant[i]][level[i]];
    for (const auto& [who, per_level] : ratings_of) {
        if (per_level.size() < pair.levels.size())
            return "participant " + who + " did not rate every level";
        for (const auto& [l, count] : per_level)
            if (count < 2) return "participant " + who + " rated level " + l + " once";
    }
    const std::size_t k = pair.levels.size(), parameters = k * (k + 1) / 2;
    if (ratings_of.size() <= parameters)
        return std::to_string(ratings_of.size()) + " participants for a " +
               std::to_string(k) + " x " + std::to_string(k) + " covariance (" +
               std::to_string(parameters) + " parameters)";
    return "";
}

RatingModelFit fit_linear(const PairFrame& pair, const RandomStructure& structure,
                          bool random_slopes) {
    RatingModelFit fit = empty_fit(RatingModel::lmm, pair, structure);
    if (!structure.participant && !structure.stimulus) {
        fit.notes.push_back(
            "No random effect is left, so the linear mixed model is the one-way ANOVA "
            "above; it is not fitted again.");
        return fit;
    }
    mixed::LmmSpec spec;
    spec.y = Eigen::Map<const Eigen::VectorXd>(pair.ratings.data(),
                                               Eigen::Index(pair.ratings.size()));
    spec.fixed = mixed::fixed_design(pair.frame, {{"level", true, pair.levels}}, true);
    bool slopes = false;
    if (structure.participant && random_slopes) {
        const std::string why_not = why_slopes_not_identified(pair);
        slopes = why_not.empty();
        if (slopes)
            fit.formula = "rating ~ level + (1 + level | participant)" +
                          std::string(structure.stimulus ? " + (1 | stimulus)" : "");
        else
            fit.notes.push_back(
                "Random slopes for level within participant are not "
                "identified (" +
                why_not + "), so the participants get intercepts only.");
    }
    if (structure.participant) {
        std::vector<std::string> level_columns(spec.fixed.names.begin() + 1,
                                               spec.fixed.names.end());
        const FactorColumn participant = pair.frame.factor("participant");
        spec.random.push_back(
            slopes ? mixed::random_slopes(participant, spec.fixed, level_columns)
                   : mixed::random_intercept(participant));
    }
    if (structure.stimulus)
        spec.random.push_back(mixed::random_intercept(pair.frame.factor("stimulus")));
    try {
        const mixed::LmmFit lmm = mixed::fit_lmm(spec);
        fit.fitted = true;
        fit.log_likelihood = finite(lmm.log_likelihood);
        for (const auto& note : lmm.notes) fit.notes.push_back(note);
        for (std::size_t j = 1; j < lmm.fixed.size(); ++j) {
            const auto& effect = lmm.fixed[j];
            LevelEffect level{
                pair.levels[j], effect.estimate, effect.standard_error, {}, {}, true};
            if (effect.df && effect.standard_error > 0.0) {
                const boost::math::students_t t(*effect.df);
                const double half =
                    boost::math::quantile(t, 0.975) * effect.standard_error;
                level.low = effect.estimate - half;
                level.high = effect.estimate + half;
            }
            fit.effects.push_back(level);
        }
        for (const auto& component : lmm.components)
            if (component.name_b.empty())
                fit.random_sds.emplace_back(
                    component.group +
                        (component.name_a.empty() || component.name_a == "(Intercept)"
                             ? ""
                             : " " + component.name_a),
                    component.sd_or_correlation);
        if (!lmm.anova.empty()) {
            const auto& test = lmm.anova.front();
            fit.statistic = test.f;
            fit.df = double(test.num_df);
            fit.den_df = test.den_df;
            fit.p = test.p;
        }
        spec.start_theta = lmm.theta;
        mixed::LmmSpec reduced = spec;
        reduced.fixed = mixed::fixed_design(pair.frame, {}, true);
        const auto lr = mixed::likelihood_ratio(reduced, spec);
        fit.lr_chi_square = finite(lr.chi_square);
        fit.lr_df = double(lr.df);
        fit.lr_p = finite(lr.p);
    } catch (const InputError& error) {
        fit.notes.push_back(std::string("Not fitted: ") + error.what() + ".");
    }
    return fit;
}

// The rating categories: every integer point of the scale the ratings use, or nothing
// when the ratings are not integers on at most kMostCategories points.
std::vector<std::string> ordinal_categories(const std::vector<double>& ratings) {
    if (ratings.empty()) return {};
    double low = ratings[0], high = ratings[0];
    for (double r : ratings) {
        if (r != std::round(r)) return {};
        low = std::min(low, r);
        high = std::max(high, r);
    }
    if (high - low + 1 > kMostCategories) return {};
    std::vector<std::string> categories;
    for (double v = low; v <= high; v += 1.0)
        categories.push_back(common::shortest_text(v));
    return categories;
}

double link_cdf(mixed::Link link, double x) {
    if (link == mixed::Link::Probit) return 0.5 * std::erfc(-x / std::sqrt(2.0));
    return 1.0 / (1.0 + std::exp(-x));
}

// P(rating = category | level) at random effects zero, for every category (unused
// ones, which the model dropped, get 0).
void add_probabilities(const mixed::ClmmFit& clmm, const PairFrame& pair,
                       RatingModelFit& fit) {
    std::map<std::string, double> effect_of_level;
    for (std::size_t j = 1; j < pair.levels.size(); ++j)
        for (const auto& coefficient : clmm.coefficients)
            if (coefficient.name == "level" + pair.levels[j])
                effect_of_level[pair.levels[j]] = coefficient.estimate;
    const auto& level = pair.frame.text("level");
    const auto& rating = pair.frame.text("rating");
    for (const auto& l : pair.levels) {
        const double eta = effect_of_level.count(l) ? effect_of_level[l] : 0.0;
        std::vector<double> predicted(fit.categories.size(), 0.0),
            observed(fit.categories.size(), 0.0);
        double below = 0.0;
        for (std::size_t k = 0; k < clmm.response_levels.size(); ++k) {
            const double at_or_below =
                k + 1 < clmm.response_levels.size()
                    ? link_cdf(clmm.link, clmm.thresholds[k].estimate - eta)
                    : 1.0;
            const auto c = std::find(fit.categories.begin(), fit.categories.end(),
                                     clmm.response_levels[k]) -
                           fit.categories.begin();
            if (std::size_t(c) < predicted.size())
                predicted[std::size_t(c)] = at_or_below - below;
            below = at_or_below;
        }
        double count = 0.0;
        for (std::size_t i = 0; i < level.size(); ++i)
            if (level[i] == l) {
                const auto c =
                    std::find(fit.categories.begin(), fit.categories.end(), rating[i]) -
                    fit.categories.begin();
                observed[std::size_t(c)] += 1.0;
                count += 1.0;
            }
        for (double& o : observed) o /= std::max(count, 1.0);
        fit.predicted.push_back(std::move(predicted));
        fit.observed.push_back(std::move(observed));
    }
}

RatingModelFit fit_ordinal(const PairFrame& pair, const RandomStructure& structure) {
    RatingModelFit fit = empty_fit(RatingModel::clmm, pair, structure);
    fit.categories = ordinal_categories(pair.ratings);
    if (fit.categories.empty()) {
        fit.notes.push_back("The ratings are not whole points on a scale of at most " +
                            std::to_string(kMostCategories) +
                            ", so the ordinal model is not fitted (the linear one is).");
        return fit;
    }
    mixed::ClmmSpec spec;
    spec.response = pair.frame.factor("rating", fit.categories);
    spec.fixed = mixed::fixed_design(pair.frame, {{"level", true, pair.levels}}, false);
    if (structure.participant)
        spec.random_intercepts.push_back(pair.frame.factor("participant"));
    if (structure.stimulus)
        spec.random_intercepts.push_back(pair.frame.factor("stimulus"));
    try {
        // The reduced model of the likelihood-ratio test is fitted on another thread at
        // the same time as the full one (the two fits are independent).
        std::future<mixed::ClmmFit> reduced;
        if (!mixed::columns_of_term(spec.fixed, "level").empty())
            reduced =
                std::async(std::launch::async,
                           [reduced_spec = mixed::clmm_without_term(spec, "level")] {
                               return mixed::fit_clmm(reduced_spec);
                           });
        const mixed::ClmmFit clmm = mixed::fit_clmm(spec);
        fit.fitted = true;
        fit.log_likelihood = finite(clmm.log_likelihood);
        for (const auto& note : clmm.notes) fit.notes.push_back(note);
        for (const auto& coefficient : clmm.coefficients) {
            LevelEffect level{coefficient.name.substr(5),
                              coefficient.estimate,
                              coefficient.std_error,
                              {},
                              {},
                              coefficient.estimable};
            if (coefficient.estimable && coefficient.std_error > 0.0) {
                level.low = coefficient.estimate - kNormal975 * coefficient.std_error;
                level.high = coefficient.estimate + kNormal975 * coefficient.std_error;
            }
            fit.effects.push_back(level);
        }
        for (const auto& grouping : clmm.groupings)
            if (grouping.identifiable)
                fit.random_sds.emplace_back(grouping.name, grouping.sd);
        const auto test =
            reduced.valid()
                ? mixed::clmm_likelihood_ratio_test(clmm, reduced.get(), "level")
                : mixed::clmm_likelihood_ratio_test(spec, clmm, "level");
        for (const auto& note : test.notes)
            if (std::find(fit.notes.begin(), fit.notes.end(), note) == fit.notes.end())
                fit.notes.push_back(note);
        if (test.df > 0) {
            fit.statistic = finite(test.chi_square);
            fit.df = double(test.df);
            fit.p = finite(test.p);
        }
        add_probabilities(clmm, pair, fit);
    } catch (const InputError& error) {
        fit.notes.push_back(std::string("Not fitted: ") + error.what() + ".");
    }
    return fit;
}

}  // namespace

const char* rating_model_name(RatingModel model) {
    switch (model) {
        case RatingModel::anova:
            return "anova";
        case RatingModel::lmm:
            return "lmm";
        case RatingModel::clmm:
            return "clmm";
    }
    return "anova";
}

bool ModelChoice::runs(RatingModel model) const {
    return model == RatingModel::anova ? anova : model == RatingModel::lmm ? lmm : clmm;
}

RatingModel parse_rating_model(const std::string& text, const std::string& what) {
    for (RatingModel model : {RatingModel::anova, RatingModel::lmm, RatingModel::clmm})
        if (text == rating_model_name(model)) return model;
    throw InputError(what + ": '" + text + "' is not one of anova, lmm, clmm");
}

ModelChoice parse_model_list(const std::string& list, RatingModel primary) {
    ModelChoice choice;
    choice.anova = choice.lmm = choice.clmm = false;
    std::vector<RatingModel> listed;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        const RatingModel model =
            parse_rating_model(list.substr(start, comma - start), "--model");
        (model == RatingModel::anova ? choice.anova
         : model == RatingModel::lmm ? choice.lmm
                                     : choice.clmm) = true;
        listed.push_back(model);
        start = comma + 1;
    }
    choice.primary = choice.runs(primary) ? primary : listed.front();
    return choice;
}

PairModels fit_pair_models(const LongTable& table, const std::string& question,
                           const std::string& factor,
                           const std::vector<std::string>& levels,
                           const ModelChoice& choice, const ModelFitHook& on_fit) {
    PairModels models;
    if (!choice.lmm && !choice.clmm) return models;
    // Each model between the hook's two calls.
    const auto fit = [&](RatingModel model, const auto& make) {
        if (on_fit) on_fit(model, nullptr);
        RatingModelFit result = make();
        if (on_fit) on_fit(model, &result);
        return result;
    };
    const PairFrame pair = pair_frame(table, question, factor, levels);
    RandomStructure structure = random_structure(pair);
    std::map<std::string, int> ratings_per_level;
    for (const auto& level : pair.frame.text("level")) ++ratings_per_level[level];
    const bool one_rating_each =
        std::all_of(ratings_per_level.begin(), ratings_per_level.end(),
                    [](const auto& entry) { return entry.second < 2; });
    if (pair.levels.size() >= 2 && one_rating_each) {
        structure.notes.insert(
            structure.notes.begin(),
            "Needs at least 2 ratings in some level (each level has 1): "
            "a model with a parameter per level fits them exactly, so "
            "no model is fitted.");
        if (choice.lmm)
            models.lmm = fit(RatingModel::lmm, [&] {
                return empty_fit(RatingModel::lmm, pair, structure);
            });
        if (choice.clmm)
            models.clmm = fit(RatingModel::clmm, [&] {
                return empty_fit(RatingModel::clmm, pair, structure);
            });
        return models;
    }
    if (pair.levels.size() < 2) {
        structure.notes.insert(structure.notes.begin(),
                               std::to_string(pair.levels.size()) +
                                   " level with ratings: there is nothing to compare, so "
                                   "no model is fitted.");
        if (choice.lmm)
            models.lmm = fit(RatingModel::lmm, [&] {
                return empty_fit(RatingModel::lmm, pair, structure);
            });
        if (choice.clmm)
            models.clmm = fit(RatingModel::clmm, [&] {
                return empty_fit(RatingModel::clmm, pair, structure);
            });
        return models;
    }
    if (choice.lmm)
        models.lmm = fit(RatingModel::lmm, [&] {
            return fit_linear(pair, structure, choice.random_slopes);
        });
    if (choice.clmm)
        models.clmm =
            fit(RatingModel::clmm, [&] { return fit_ordinal(pair, structure); });
    return models;
}

}  // namespace lucent::analysis
