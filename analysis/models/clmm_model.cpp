// The ordinal mixed model of a pair: a cumulative link mixed model, logit link, flexible
// thresholds, rating ~ level + (1 | participant) + (1 | stimulus) (R's ordinal::clmm,
// Laplace approximation); the level tested by a likelihood ratio. Ratings that are not
// whole points on a short scale are not fitted (the linear model is).
#include <algorithm>
#include <cmath>
#include <future>
#include <map>

#include "analysis/mixed/clmm.h"
#include "analysis/models/rating_model.h"
#include "analysis/report/format.h"
#include "analysis/report/mixed_sections.h"
#include "analysis/report/ordinal_figure.h"
#include "analysis/simulate/crossed_power.h"
#include "common/number_text.h"

namespace lucent::analysis {
namespace {

constexpr double kNormal975 = 1.959963984540054;  // qnorm(0.975)
// Ordinal models for ratings on at most this many integer points; beyond it a rating is
// a number (a slider), not a category.
constexpr int kMostCategories = 11;

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
    RatingModelFit fit = empty_fit("clmm", pair, structure);
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

std::vector<Block> ordinal_blocks(const OneWayAnalysis& pair, const RatingModelFit& fit) {
    std::vector<Block> doc;
    doc.push_back({Block::kHeading, "Ordinal mixed model (clmm)", {}, {}, 3});
    std::string model =
        "Cumulative link mixed model, logit link, flexible thresholds: " + fit.formula +
        " (R: ordinal::clmm; Laplace approximation); " + fit_counts_text(fit) + ".";
    if (!fit.fitted) {
        doc.push_back({Block::kParagraph, model + " Not fitted. " + fit_notes_text(fit)});
        return doc;
    }
    doc.push_back({Block::kParagraph, model});
    doc.push_back({Block::kParagraph,
                   "Likelihood-ratio test of " + pair.factor + ": chi-square = " +
                       format_short(fit.statistic) + ", df = " + format_short(fit.df) +
                       ", p = " + format_p_short(fit.p) +
                       ". Random-effect standard deviations (logit scale): " +
                       random_sds_text(fit) + "."});
    Table effects{
        {"level", "log odds vs " + fit.reference_level, "SE", "95% CI", "odds ratio"},
        {}};
    for (const LevelEffect& e : fit.effects) {
        if (!e.estimable) {
            effects.rows.push_back(
                {e.level, "not estimable (runs to infinity)", "", "", ""});
            continue;
        }
        effects.rows.push_back(
            {e.level, format_short(e.estimate), format_short(e.standard_error),
             interval_text(e.low, e.high), format_short(std::exp(e.estimate))});
    }
    doc.push_back({Block::kTable, "", effects});
    doc.push_back({Block::kParagraph,
                   "A positive log odds means higher ratings than at " +
                       fit.reference_level +
                       ". The figure shows the model's probability of each rating per "
                       "level for a typical participant and stimulus (random effects at "
                       "zero) beside the observed proportions."});
    if (!fit.predicted.empty()) {
        Block plot{
            Block::kPlot, ordinal_plot_file_name(pair.question, pair.factor), {}, {}};
        plot.svg = ordinal_probability_svg(pair.question + " ~ " + pair.factor,
                                           pair.factor, fit.levels, fit.categories,
                                           fit.predicted, fit.observed);
        doc.push_back(plot);
    }
    if (!fit.notes.empty())
        doc.push_back({Block::kParagraph, "Note: " + fit_notes_text(fit)});
    return doc;
}

// The power simulation's fit: the crossed design's responses as categories 1..7 (those
// used), two random intercepts, the likelihood ratio of the level.
Statistic crossed_clmm_p(const CrossedSample& study) {
    mixed::ClmmSpec spec;
    spec.response.name = "rating";
    std::vector<int> used(8, 0);
    for (double y : study.y) used[std::size_t(y)] = 1;
    std::vector<int> code_of(8, -1);
    for (int v = 1; v <= 7; ++v)
        if (used[std::size_t(v)]) {
            code_of[std::size_t(v)] = int(spec.response.levels.size());
            spec.response.levels.push_back(std::to_string(v));
        }
    if (spec.response.levels.size() < 2) return std::nullopt;
    for (double y : study.y) spec.response.codes.push_back(code_of[std::size_t(y)]);
    spec.fixed = crossed_level_design(study, false);
    spec.random_intercepts = {study.participant, study.stimulus};
    const mixed::ClmmFit fit = mixed::fit_clmm(spec);
    const auto test = mixed::clmm_likelihood_ratio_test(spec, fit, "level");
    if (test.df <= 0 || !std::isfinite(test.p)) return std::nullopt;
    return test.p;
}

}  // namespace

const RatingModelSpec& clmm_model() {
    static const RatingModelSpec model{
        .name = "clmm",
        .ran =
            "ordinal mixed model (clmm) per (question, factor) with participants and "
            "stimuli as random effects; ",
        .title = "ordinal mixed model (clmm)",
        .test = "likelihood ratio (chi-square)",
        .help = "clmm (ordinal mixed model)",
        .fit = [](const PairFrame& pair, const RandomStructure& structure,
                  const ModelChoice&) { return fit_ordinal(pair, structure); },
        .blocks = ordinal_blocks,
        .crossed_p = crossed_clmm_p,
        .rounds_to_scale = true};
    return model;
}

}  // namespace lucent::analysis
