#include "analysis/report/mixed_sections.h"

#include <cctype>
#include <cmath>
#include <sstream>

#include "analysis/models/rating_model.h"
#include "analysis/report/format.h"
#include "analysis/report/ordinal_figure.h"
#include "common/csv.h"

namespace lucent::analysis {

std::string interval_text(const Statistic& low, const Statistic& high) {
    if (!low || !high) return "undefined";
    return "[" + format_short(low) + ", " + format_short(high) + "]";
}

std::string fit_notes_text(const RatingModelFit& fit) {
    std::string text;
    for (const auto& note : fit.notes) text += (text.empty() ? "" : " ") + note;
    return text;
}

std::string fit_counts_text(const RatingModelFit& fit) {
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

std::string ordinal_plot_file_name(const std::string& question,
                                   const std::string& factor) {
    std::string name = "ordinal_" + question + "_" + factor;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    return name + ".svg";
}

std::vector<std::string> mixed_summary_cells(const OneWayAnalysis& pair,
                                             const RatingModelSpec& model, double alpha) {
    const RatingModelFit* fit = pair.models.of(model.name);
    if (!fit) return {};
    const std::string& test = model.test;
    std::string verdict;
    if (fit->p)
        verdict = *fit->p < alpha ? "yes" : "no";
    else
        verdict = "undefined: " +
                  (fit->notes.empty() ? std::string("not fitted") : fit->notes.front());
    return {test, format_p_short(fit->p), format_short(fit->statistic), verdict,
            fit_counts_text(*fit)};
}

std::vector<Block> mixed_model_blocks(const OneWayAnalysis& pair) {
    std::vector<Block> doc;
    for (const RatingModelFit& fit : pair.models.fits)
        if (const RatingModelSpec* model = find_rating_model(fit.model)) {
            const std::vector<Block> blocks = model->blocks(pair, fit);
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
        for (const RatingModelFit& f : a.models.fits) {
            any = true;
            const std::string key = common::csv_field(a.question) + ',' +
                                    common::csv_field(a.factor) + ',' +
                                    common::csv_field(f.model) + ',';
            tests << key << common::csv_field(f.formula) << ','
                  << format_full(f.statistic) << ',' << format_full(f.df) << ','
                  << format_full(f.den_df) << ',' << format_p_full(f.p) << ','
                  << format_full(f.lr_chi_square) << ',' << format_full(f.lr_df) << ','
                  << format_p_full(f.lr_p) << ',' << format_full(f.log_likelihood) << ','
                  << f.participants << ',' << f.stimuli << ',' << f.observations << ','
                  << common::csv_field(fit_notes_text(f)) << '\n';
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
