#include "analysis/scaling/scaling_report.h"

#include <cmath>
#include <sstream>

#include "analysis/report/format.h"
#include "analysis/report/report.h"
#include "common/csv.h"
#include "common/html/svg_plot.h"

namespace lucent::analysis {
namespace {

constexpr double kZ95 = 1.959963984540054;

double or_nan(const std::optional<double>& v) { return v ? *v : NAN; }

// The x of each stimulus: its series value when every one has a value, else 1..p.
std::vector<double> x_positions(const std::vector<std::optional<double>>& values,
                                std::string& label) {
    std::vector<double> x;
    bool all = !values.empty();
    for (const auto& v : values) all = all && v.has_value();
    for (std::size_t i = 0; i < values.size(); ++i)
        x.push_back(all ? *values[i] : static_cast<double>(i + 1));
    if (!all) label = "position in the series";
    return x;
}

// One scale per fit: value, low and high end of its interval (NaN where none).
struct Curve {
    std::vector<double> y, low, high;
};

Curve curve_of(const PairedFit& fit) {
    Curve c;
    for (const StimulusAbility& a : fit.abilities) {
        c.y.push_back(or_nan(a.ability));
        c.low.push_back(a.ability && a.se ? *a.ability - kZ95 * *a.se : NAN);
        c.high.push_back(a.ability && a.se ? *a.ability + kZ95 * *a.se : NAN);
    }
    return c;
}

Curve curve_of(const MldsFit& fit) {
    Curve c;
    for (std::size_t j = 0; j < fit.scale.size(); ++j) {
        c.y.push_back(or_nan(fit.scale[j]));
        if (fit.ci_low[j] && fit.ci_high[j]) {  // the bootstrap's percentile interval
            c.low.push_back(*fit.ci_low[j]);
            c.high.push_back(*fit.ci_high[j]);
        } else if (fit.scale[j] && fit.se[j]) {
            c.low.push_back(*fit.scale[j] - kZ95 * *fit.se[j]);
            c.high.push_back(*fit.scale[j] + kZ95 * *fit.se[j]);
        } else {
            c.low.push_back(NAN);
            c.high.push_back(NAN);
        }
    }
    return c;
}

template <class Fits>
std::string plot_svg(const std::string& title, const std::string& y_label,
                     const std::string& interval, const std::vector<double>& x,
                     const std::string& x_label, const Curve& pooled,
                     const Fits& participants) {
    common::PlotPanel panel;
    panel.title = title;
    panel.x_label = x_label + " (pooled with " + interval + "; a line per participant)";
    panel.y_label = y_label;
    panel.x = x;
    panel.y = pooled.y;
    panel.y_low = pooled.low;
    panel.y_high = pooled.high;
    panel.x_axis.scale = common::AxisScale::linear;
    panel.y_axis.scale = common::AxisScale::linear;
    if (participants.size() > 1) {
        for (const auto& [name, fit] : participants)
            panel.series.push_back({name, x, curve_of(fit).y});
        panel.series_behind = true;
        panel.main_label = "pooled";
    }
    return common::figure_svg("", {panel}, {560, 360, 1});
}

std::string cell(const std::optional<double>& v) { return format_short(v); }

std::string scaled_name(const std::string& block) { return "scaling_" + block; }

Block paragraph(std::string text) { return {Block::kParagraph, std::move(text), {}, {}}; }

void add_notes(std::vector<Block>& blocks, const std::string& who,
               const std::vector<std::string>& notes) {
    for (const std::string& n : notes) blocks.push_back(paragraph(who + n));
}

// A participant's notes, with the unbounded abilities (one sentence per stimulus in the
// fit, common with few comparisons each) said in one sentence.
void add_participant_notes(std::vector<Block>& blocks, const std::string& who,
                           const PairedFit& fit) {
    std::vector<std::string> above, below, others;
    for (const std::string& n : fit.notes) {
        if (n.find("its ability is unbounded") == std::string::npos) {
            others.push_back(n);
            continue;
        }
        const std::string stimulus = n.substr(0, n.find(' '));
        (n.find(" won ") < n.find(':') ? above : below).push_back(stimulus);
    }
    auto listed = [](const std::vector<std::string>& ids) {
        std::string out;
        for (const std::string& id : ids) out += (out.empty() ? "" : ", ") + id;
        return out;
    };
    if (!above.empty() || !below.empty())
        blocks.push_back(paragraph(
            who +
            ": unbounded abilities (each won or lost every comparison linking it to "
            "the others): " +
            (above.empty() ? "" : listed(above) + " above") +
            (above.empty() || below.empty() ? "" : "; ") +
            (below.empty() ? "" : listed(below) + " below") + "."));
    add_notes(blocks, who + ": ", others);
}

Block pictures_block(const std::vector<std::string>& stimuli,
                     const std::vector<std::optional<double>>& values,
                     const std::map<std::string, std::filesystem::path>& pictures) {
    Block images{Block::kImages, "", {}, {}};
    for (std::size_t i = 0; i < stimuli.size(); ++i) {
        const auto it = pictures.find(stimuli[i]);
        if (it == pictures.end()) continue;
        images.images.push_back(
            {stimuli[i] + (values[i] ? " (" + format_short(values[i]) + ")" : ""),
             it->second});
    }
    return images;
}

void csv_row(std::ostringstream& csv, const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i)
        csv << (i ? "," : "") << common::csv_field(fields[i]);
    csv << '\n';
}

}  // namespace

ScalingSection scaling_section(
    const std::vector<PairedBlockFits>& paired, const std::vector<MldsBlockFits>& mlds,
    const std::map<std::string, std::filesystem::path>& pictures) {
    ScalingSection section;
    if (paired.empty() && mlds.empty()) return section;
    std::ostringstream csv;
    csv_row(csv, {"block", "question", "method", "participant", "stimulus", "value",
                  "scale", "se", "ci_low", "ci_high"});
    section.blocks.push_back({Block::kHeading, "Perceptual scales", {}, {}, 2});

    for (const PairedBlockFits& b : paired) {
        const PairedFit& f = b.pooled;
        section.blocks.push_back({Block::kHeading,
                                  b.block + ": " + b.question + " (paired comparisons)",
                                  {},
                                  {},
                                  3});
        section.blocks.push_back(paragraph(
            f.model + " abilities, " + (f.abilities.empty() ? std::string("-")
                                                             : [&] {
                                                                   for (const auto& a : f.abilities)
                                                                       if (a.reference)
                                                                           return a.stimulus;
                                                                   return std::string("none");
                                                               }()) +
            " = 0; " + std::to_string(b.participants.size()) + " participants; catch trials: " +
            std::to_string(b.catch_trials) + ", " + std::to_string(b.catch_failed) +
            " answered wrongly. Deviance " + cell(f.deviance) + " on " +
            std::to_string(f.df_residual) + " df (goodness of fit p = " + format_p_short(f.fit_p) +
            "), AIC " + cell(f.aic) + "; against all-equal abilities: chi-square " +
            cell(f.lr_chi2) + " on " + std::to_string(f.parameters) + " df, p = " +
            format_p_short(f.lr_p) + "."));
        add_notes(section.blocks, "", f.notes);
        std::string x_label = "series value";
        const std::vector<double> x = x_positions(b.values, x_label);
        const std::string file = plot_file_name(b.question, scaled_name(b.block));
        Block plot{Block::kPlot, file, {}, {}};
        plot.svg = plot_svg(b.block, "ability", "95% CI", x, x_label, curve_of(f),
                            b.participants);
        section.files.emplace_back(file, plot.svg);
        section.blocks.push_back(plot);
        if (Block images = pictures_block(b.stimuli, b.values, pictures);
            !images.images.empty())
            section.blocks.push_back(images);
        // Both scales: the fit's link and the other (Bradley-Terry and Thurstone).
        const PairedFit& g = b.pooled_other_link;
        auto ability_cell = [](const StimulusAbility& a) {
            return a.unbounded > 0   ? std::string("unbounded above")
                   : a.unbounded < 0 ? std::string("unbounded below")
                                     : cell(a.ability);
        };
        Table t{
            {"stimulus", "value", f.model, "SE", g.model, "SE", "wins", "comparisons"},
            {}};
        for (std::size_t i = 0; i < f.abilities.size(); ++i) {
            const StimulusAbility& a = f.abilities[i];
            const bool other = i < g.abilities.size();
            t.rows.push_back({a.stimulus, cell(b.values[i]), ability_cell(a), cell(a.se),
                              other ? ability_cell(g.abilities[i]) : std::string("-"),
                              other ? cell(g.abilities[i].se) : std::string("-"),
                              format_short(a.wins), format_short(a.comparisons)});
        }
        if (!g.model.empty())
            section.blocks.push_back(paragraph(
                g.model + ": deviance " + cell(g.deviance) + " on " +
                std::to_string(g.df_residual) + " df, AIC " + cell(g.aic) + "."));
        section.blocks.push_back({Block::kTable, "", t, {}});
        Table per{{"participant", "deviance", "df", "AIC", "all-equal p",
                   "first shown chosen", "position p"},
                  {}};
        for (const auto& [who, pf] : b.participants) {
            per.rows.push_back({who, cell(pf.deviance), std::to_string(pf.df_residual),
                                cell(pf.aic), format_p_short(pf.lr_p),
                                pf.position.share
                                    ? format_short(100.0 * *pf.position.share) + "%"
                                    : "undefined",
                                format_p_short(pf.position.p)});
            add_participant_notes(section.blocks, who, pf);
        }
        section.blocks.push_back({Block::kTable, "", per, {}});
        auto rows_of = [&](const std::string& who, const PairedFit& pf) {
            for (std::size_t i = 0; i < pf.abilities.size(); ++i) {
                const auto& a = pf.abilities[i];
                const Curve c = curve_of(pf);
                csv_row(csv, {b.block, b.question, pf.model, who, a.stimulus,
                              format_full(b.values[i]), format_full(a.ability),
                              format_full(a.se),
                              format_full(std::isnan(c.low[i]) ? Statistic()
                                                               : Statistic(c.low[i])),
                              format_full(std::isnan(c.high[i]) ? Statistic()
                                                                : Statistic(c.high[i]))});
            }
        };
        rows_of("(pooled)", f);
        rows_of("(pooled)", g);
        for (const auto& [who, pf] : b.participants) rows_of(who, pf);
    }

    for (const MldsBlockFits& b : mlds) {
        const MldsFit& f = b.pooled;
        section.blocks.push_back(
            {Block::kHeading,
             b.block + ": " + b.question + " (difference scaling, MLDS)",
             {},
             {},
             3});
        section.blocks.push_back(paragraph(
            "Scale by the GLM of Knoblauch and Maloney (2008), psi_1 = 0 and psi_" +
            std::to_string(b.stimuli.size()) + " = 1; " + std::to_string(f.trials) +
            " judgements of " + std::to_string(b.participants.size()) +
            " participants; catch trials: " + std::to_string(b.catch_trials) + ", " +
            std::to_string(b.catch_failed) + " answered wrongly. sigma " + cell(f.sigma) +
            " (SE " + cell(f.sigma_se) + "), log-likelihood " + cell(f.log_likelihood) +
            ", AIC " + cell(f.aic) + ", deviance accounted for (DAF) " +
            (f.daf ? format_short(100.0 * *f.daf) + "%" : std::string("undefined")) +
            "; six-point test: " + std::to_string(f.six_point.violations) + " of " +
            std::to_string(f.six_point.sets) + " sets violated" +
            (f.six_point.p ? ", p = " + format_p_short(f.six_point.p) + " (" +
                                 std::to_string(f.six_point.simulations) + " simulations)"
                           : std::string()) +
            "."));
        add_notes(section.blocks, "", f.notes);
        std::string x_label = "series value";
        const std::vector<double> x = x_positions(b.values, x_label);
        const std::string file = plot_file_name(b.question, scaled_name(b.block));
        Block plot{Block::kPlot, file, {}, {}};
        plot.svg = plot_svg(b.block, "perceptual scale",
                            f.bootstrap_samples > 0 ? "bootstrap 95% interval" : "95% CI",
                            x, x_label, curve_of(f), b.participants);
        section.files.emplace_back(file, plot.svg);
        section.blocks.push_back(plot);
        if (Block images = pictures_block(b.stimuli, b.values, pictures);
            !images.images.empty())
            section.blocks.push_back(images);
        Table t{{"stimulus", "value", "scale", "SE", "interval", "scale (sigma = 1)"},
                {}};
        for (std::size_t i = 0; i < b.stimuli.size(); ++i)
            t.rows.push_back(
                {b.stimuli[i], cell(b.values[i]), cell(f.scale[i]), cell(f.se[i]),
                 f.ci_low[i] && f.ci_high[i]
                     ? format_short(f.ci_low[i]) + " .. " + format_short(f.ci_high[i])
                     : std::string("-"),
                 cell(f.glm_scale[i])});
        section.blocks.push_back({Block::kTable, "", t, {}});
        Table per{{"participant", "judgements", "sigma", "DAF", "AIC", "six-point p"},
                  {}};
        for (const auto& [who, pf] : b.participants) {
            per.rows.push_back(
                {who, std::to_string(pf.trials), cell(pf.sigma),
                 pf.daf ? format_short(100.0 * *pf.daf) + "%" : "undefined", cell(pf.aic),
                 format_p_short(pf.six_point.p)});
            add_notes(section.blocks, who + ": ", pf.notes);
        }
        section.blocks.push_back({Block::kTable, "", per, {}});
        auto rows_of = [&](const std::string& who, const MldsFit& mf) {
            const Curve c = curve_of(mf);
            for (std::size_t i = 0; i < mf.stimuli.size(); ++i)
                csv_row(csv, {b.block, b.question, "MLDS (probit GLM; psi_p = 1)", who,
                              mf.stimuli[i], format_full(b.values[i]),
                              format_full(mf.scale[i]), format_full(mf.se[i]),
                              format_full(std::isnan(c.low[i]) ? Statistic()
                                                               : Statistic(c.low[i])),
                              format_full(std::isnan(c.high[i]) ? Statistic()
                                                                : Statistic(c.high[i]))});
        };
        rows_of("(pooled)", f);
        for (const auto& [who, pf] : b.participants) rows_of(who, pf);
    }
    section.files.emplace_back("scaling.csv", csv.str());
    return section;
}

}  // namespace lucent::analysis
