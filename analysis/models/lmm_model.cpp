// The linear mixed model of a pair: rating ~ level + (1 | participant) + (1 | stimulus)
// (R's lme4::lmer, REML), the level tested by Satterthwaite's F (lmerTest's anova) and
// by a likelihood ratio of ML refits; with --random-slopes, (1 + level | participant)
// where the design identifies it.
#include <boost/math/distributions/students_t.hpp>
#include <map>

#include "analysis/mixed/lmm.h"
#include "analysis/models/rating_model.h"
#include "analysis/report/format.h"
#include "analysis/report/mixed_sections.h"
#include "analysis/simulate/crossed_power.h"

namespace lucent::analysis {
namespace {

using mixed::FactorColumn;

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
    RatingModelFit fit = empty_fit("lmm", pair, structure);
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

std::vector<Block> linear_blocks(const OneWayAnalysis& pair, const RatingModelFit& fit) {
    std::vector<Block> doc;
    doc.push_back({Block::kHeading, "Linear mixed model (lmm)", {}, {}, 3});
    std::string model = "Linear mixed model, REML: " + fit.formula +
                        " (R: lme4::lmer with lmerTest); " + fit_counts_text(fit) + ".";
    if (!fit.fitted) {
        doc.push_back({Block::kParagraph, model + " Not fitted. " + fit_notes_text(fit)});
        return doc;
    }
    doc.push_back({Block::kParagraph, model});
    doc.push_back({Block::kParagraph,
                   "Type III test of " + pair.factor +
                       " (Satterthwaite): F = " + format_short(fit.statistic) +
                       ", df = " + format_short(fit.df) + " and " +
                       format_short(fit.den_df) + ", p = " + format_p_short(fit.p) +
                       ". Likelihood ratio (ML refits): chi-square = " +
                       format_short(fit.lr_chi_square) + ", df = " +
                       format_short(fit.lr_df) + ", p = " + format_p_short(fit.lr_p) +
                       ". Standard deviations: " + random_sds_text(fit) + "."});
    Table effects{{"level", "difference vs " + fit.reference_level, "SE", "95% CI"}, {}};
    for (const LevelEffect& e : fit.effects)
        effects.rows.push_back({e.level, format_short(e.estimate),
                                format_short(e.standard_error),
                                interval_text(e.low, e.high)});
    doc.push_back({Block::kTable, "", effects});
    if (!fit.notes.empty())
        doc.push_back({Block::kParagraph, "Note: " + fit_notes_text(fit)});
    return doc;
}

// The power simulation's fit: the crossed design's two random intercepts, no frame.
Statistic crossed_lmm_p(const CrossedSample& study) {
    mixed::LmmSpec spec;
    spec.y =
        Eigen::Map<const Eigen::VectorXd>(study.y.data(), Eigen::Index(study.y.size()));
    spec.fixed = crossed_level_design(study, true);
    spec.random = {mixed::random_intercept(study.participant),
                   mixed::random_intercept(study.stimulus)};
    const mixed::LmmFit fit = mixed::fit_lmm(spec);
    return fit.anova.empty() ? std::nullopt : fit.anova.front().p;
}

}  // namespace

const RatingModelSpec& lmm_model() {
    static const RatingModelSpec model{
        .name = "lmm",
        .ran = "linear mixed model (lmm) likewise; ",
        .title = "linear mixed model (lmm)",
        .test = "Satterthwaite F",
        .help = "lmm (linear mixed model)",
        .fit =
            [](const PairFrame& pair, const RandomStructure& structure,
               const ModelChoice& choice) {
                return fit_linear(pair, structure, choice.random_slopes);
            },
        .blocks = linear_blocks,
        .crossed_p = crossed_lmm_p};
    return model;
}

}  // namespace lucent::analysis
