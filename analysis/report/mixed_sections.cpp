#include "analysis/report/mixed_sections.h"

#include <cctype>
#include <cmath>
#include <sstream>

#include "analysis/report/format.h"
#include "analysis/report/ordinal_figure.h"
#include "common/csv.h"

namespace lucent::analysis {
namespace {

const std::optional<RatingModelFit>& fit_of(const OneWayAnalysis& pair,
                                            RatingModel model) {
    return model == RatingModel::clmm ? pair.models.clmm : pair.models.lmm;
}

std::string interval(const Statistic& low, const Statistic& high) {
    if (!low || !high) return "undefined";
    return "[" + format_short(low) + ", " + format_short(high) + "]";
}

std::string notes_text(const RatingModelFit& fit) {
    std::string text;
    for (const auto& note : fit.notes) text += (text.empty() ? "" : " ") + note;
    return text;
}

std::string used(const RatingModelFit& fit) {
    return std::to_string(fit.participants) + " participants, " +
           std::to_string(fit.stimuli) + " stimuli, " + std::to_string(fit.observations) +
           " ratings";
}

std::string random_sds_text(const RatingModelFit& fit) {
    std::string text;
    for (const auto& [group, sd] : fit.random_sds)
        text += (text.empty() ? "" : ", ") + group + " " + format_short(sd);
    return text.empty() ? "none" : text;
}

std::vector<Block> ordinal_blocks(const OneWayAnalysis& pair, const RatingModelFit& fit) {
    std::vector<Block> doc;
    doc.push_back({Block::kHeading, "Ordinal mixed model (clmm)", {}, {}, 3});
    std::string model =
        "Cumulative link mixed model, logit link, flexible thresholds: " + fit.formula +
        " (R: ordinal::clmm; Laplace approximation); " + used(fit) + ".";
    if (!fit.fitted) {
        doc.push_back({Block::kParagraph, model + " Not fitted. " + notes_text(fit)});
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
        effects.rows.push_back({e.level, format_short(e.estimate),
                                format_short(e.standard_error), interval(e.low, e.high),
                                format_short(std::exp(e.estimate))});
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
        doc.push_back({Block::kParagraph, "Note: " + notes_text(fit)});
    return doc;
}

std::vector<Block> linear_blocks(const OneWayAnalysis& pair, const RatingModelFit& fit) {
    std::vector<Block> doc;
    doc.push_back({Block::kHeading, "Linear mixed model (lmm)", {}, {}, 3});
    std::string model = "Linear mixed model, REML: " + fit.formula +
                        " (R: lme4::lmer with lmerTest); " + used(fit) + ".";
    if (!fit.fitted) {
        doc.push_back({Block::kParagraph, model + " Not fitted. " + notes_text(fit)});
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
                                format_short(e.standard_error), interval(e.low, e.high)});
    doc.push_back({Block::kTable, "", effects});
    if (!fit.notes.empty())
        doc.push_back({Block::kParagraph, "Note: " + notes_text(fit)});
    return doc;
}

}  // namespace

std::string ordinal_plot_file_name(const std::string& question,
                                   const std::string& factor) {
    std::string name = "ordinal_" + question + "_" + factor;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    return name + ".svg";
}

std::vector<std::string> mixed_summary_cells(const OneWayAnalysis& pair,
                                             RatingModel model, double alpha) {
    const auto& fit = fit_of(pair, model);
    if (!fit) return {};
    const bool ordinal = model == RatingModel::clmm;
    const std::string test =
        ordinal ? "likelihood ratio (chi-square)" : "Satterthwaite F";
    std::string verdict;
    if (fit->p)
        verdict = *fit->p < alpha ? "yes" : "no";
    else
        verdict = "undefined: " +
                  (fit->notes.empty() ? std::string("not fitted") : fit->notes.front());
    return {test, format_p_short(fit->p), format_short(fit->statistic), verdict,
            used(*fit)};
}

std::vector<Block> mixed_model_blocks(const OneWayAnalysis& pair) {
    std::vector<Block> doc;
    if (pair.models.clmm) {
        auto blocks = ordinal_blocks(pair, *pair.models.clmm);
        doc.insert(doc.end(), blocks.begin(), blocks.end());
    }
    if (pair.models.lmm) {
        auto blocks = linear_blocks(pair, *pair.models.lmm);
        doc.insert(doc.end(), blocks.begin(), blocks.end());
    }
    return doc;
}

void write_mixed_csv_tables(const std::vector<OneWayAnalysis>& analyses,
                            ReportFiles& files) {
    std::ostringstream tests, effects, probabilities;
    tests
        << "question,factor,model,formula,statistic,df,den_df,p,lr_chi_square,lr_df,lr_p,"
           "log_likelihood,participants,stimuli,ratings,notes\n";
    effects
        << "question,factor,model,level,reference,estimate,se,ci_low,ci_high,estimable\n";
    probabilities << "question,factor,level,rating,predicted,observed\n";
    bool any = false;
    for (const OneWayAnalysis& a : analyses)
        for (const auto* fit : {&a.models.clmm, &a.models.lmm}) {
            if (!*fit) continue;
            any = true;
            const RatingModelFit& f = **fit;
            const std::string key = common::csv_field(a.question) + ',' +
                                    common::csv_field(a.factor) + ',' +
                                    rating_model_name(f.model) + ',';
            tests << key << common::csv_field(f.formula) << ','
                  << format_full(f.statistic) << ',' << format_full(f.df) << ','
                  << format_full(f.den_df) << ',' << format_p_full(f.p) << ','
                  << format_full(f.lr_chi_square) << ',' << format_full(f.lr_df) << ','
                  << format_p_full(f.lr_p) << ',' << format_full(f.log_likelihood) << ','
                  << f.participants << ',' << f.stimuli << ',' << f.observations << ','
                  << common::csv_field(notes_text(f)) << '\n';
            for (const LevelEffect& e : f.effects)
                effects << key << common::csv_field(e.level) << ','
                        << common::csv_field(f.reference_level) << ','
                        << format_full(e.estimable ? Statistic(e.estimate) : std::nullopt)
                        << ','
                        << format_full(e.estimable ? Statistic(e.standard_error)
                                                   : std::nullopt)
                        << ',' << format_full(e.low) << ',' << format_full(e.high) << ','
                        << (e.estimable ? "yes" : "no") << '\n';
            for (std::size_t l = 0; l < f.predicted.size(); ++l)
                for (std::size_t k = 0; k < f.categories.size(); ++k)
                    probabilities << common::csv_field(a.question) << ','
                                  << common::csv_field(a.factor) << ','
                                  << common::csv_field(f.levels[l]) << ','
                                  << common::csv_field(f.categories[k]) << ','
                                  << format_full(f.predicted[l][k]) << ','
                                  << format_full(f.observed[l][k]) << '\n';
        }
    if (!any) return;
    files.emplace_back("mixed_tests.csv", tests.str());
    files.emplace_back("mixed_effects.csv", effects.str());
    files.emplace_back("ordinal_probabilities.csv", probabilities.str());
}

}  // namespace lucent::analysis
