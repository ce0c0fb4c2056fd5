#include "analysis/matching/matching_report.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "analysis/report/format.h"
#include "analysis/report/report.h"
#include "common/csv.h"
#include "common/html/svg_plot.h"

namespace lucent::analysis {
namespace {

Block paragraph(std::string text) { return {Block::kParagraph, std::move(text), {}, {}}; }
Block heading(std::string text, int level) {
    return {Block::kHeading, std::move(text), {}, {}, level};
}

std::string cell(const std::optional<double>& v) {
    return v ? format_short(v) : std::string("-");
}

std::string interval(const std::optional<double>& low,
                     const std::optional<double>& high) {
    return low && high ? format_short(low) + " .. " + format_short(high)
                       : std::string("-");
}

std::string full(const std::optional<double>& v) { return v ? format_full(v) : ""; }

void csv_row(std::ostringstream& csv, const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i)
        csv << (i ? "," : "") << common::csv_field(fields[i]);
    csv << '\n';
}

double or_nan(const std::optional<double>& v) { return v ? *v : NAN; }

// Match against target per block: the conditions with a target value on a numeric x
// axis with the identity line; without any, one point per target by name.
std::string match_plot(const std::string& block,
                       const std::vector<const ConditionMatch*>& cs) {
    common::PlotPanel panel;
    panel.title = block;
    const std::string knob = cs.front()->knob.empty() ? "knob" : cs.front()->knob;
    panel.y_label = "match " + knob + " (mean, 95% CI)";
    panel.join = false;
    // Each condition's x: the target's value, else the same-scene match its constancy
    // index compares it with.
    auto x_of = [](const ConditionMatch* c) {
        return c->target_value ? c->target_value : c->constancy_reference;
    };
    bool any_value = false, any_reference = false;
    for (const ConditionMatch* c : cs) {
        any_value = any_value || c->target_value;
        any_reference = any_reference || (!c->target_value && c->constancy_reference);
    }
    if (any_value || any_reference) {
        panel.x_label =
            (any_reference ? (any_value ? "target's " + knob + " or its same-scene match"
                                        : "the target's same-scene match")
                           : "target's " + knob) +
            " (line: equal)";
        double lo = INFINITY, hi = -INFINITY;
        for (const ConditionMatch* c : cs) {
            if (!x_of(c) || !c->mean) continue;
            panel.x.push_back(*x_of(c));
            panel.y.push_back(*c->mean);
            panel.y_low.push_back(or_nan(c->ci_low));
            panel.y_high.push_back(or_nan(c->ci_high));
            panel.point_labels.push_back(c->target);
            for (double v :
                 {*c->target_value, *c->mean, or_nan(c->ci_low), or_nan(c->ci_high)})
                if (std::isfinite(v)) {
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                }
        }
        if (std::isfinite(lo) && std::isfinite(hi)) {
            if (hi == lo) {
                lo -= 0.5;
                hi += 0.5;
            }
            panel.series.push_back({"match = target", {lo, hi}, {lo, hi}});
            if (cs.front()->log_scale && lo > 0) {
                panel.x_axis.scale = common::AxisScale::log;
                panel.y_axis.scale = common::AxisScale::log;
            }
            panel.series_behind = true;
            panel.main_label = "mean match";
        }
    } else {
        panel.x_label = "target (a picture: no value of the knob)";
        for (const ConditionMatch* c : cs) {
            panel.categories.push_back(c->target);
            panel.y.push_back(or_nan(c->mean));
            panel.y_low.push_back(or_nan(c->ci_low));
            panel.y_high.push_back(or_nan(c->ci_high));
        }
    }
    return common::figure_svg("", {panel}, {520, 360, 1});
}

void add_matching(MatchingSection& section, const std::vector<ConditionMatch>& matches) {
    if (matches.empty()) return;
    std::ostringstream csv;
    csv_row(csv, {"block", "target", "match", "knob", "participant", "n", "mean", "sd",
                  "sd_scale", "ci_low", "ci_high", "target_value", "bias", "bias_ci_low",
                  "bias_ci_high", "constancy_index", "constancy_factor"});
    section.blocks.push_back(heading("Matching", 2));
    section.blocks.push_back(paragraph(
        "Each condition is an adjust block's target: the values of the match's knob the "
        "participants confirmed, their mean, SD and 95% t interval over the trials (and, "
        "with two or more participants, over the participant means); a log block's on "
        "log10 (geometric means, intervals back-transformed, SDs in log10 units). The "
        "bias is the "
        "mean match minus the target's own value of the knob, where the target is a "
        "live stimulus of the match's technique. The constancy index, where the target "
        "and the match differ in exactly one scene factor, is 1 - |mean match - "
        "reference| / max(reference - low end, high end - reference) on the knob's "
        "scale (its logarithm for a log block); the reference is the target's own value, "
        "or else its match in a block where target and match share every scene factor: "
        "1 is a match across the factor equal to the reference, 0 a match as far "
        "from it as the range allows."));
    Table t{{"block (knob)", "target", "n", "mean", "SD", "95% CI",
             "participant means: 95% CI", "target value", "bias", "bias 95% CI",
             "constancy index"},
            {}};
    std::map<std::string, std::vector<const ConditionMatch*>> by_block;
    std::vector<std::string> block_order;
    for (const ConditionMatch& c : matches) {
        if (by_block[c.block].empty()) block_order.push_back(c.block);
        by_block[c.block].push_back(&c);
        t.rows.push_back(
            {c.block + (c.knob.empty() ? std::string() : " (" + c.knob + ")"), c.target,
             std::to_string(c.n), cell(c.mean),
             c.n < 2      ? std::string("- (one match)")
             : c.on_log10 ? cell(c.sd) + " (log10)"
                          : cell(c.sd),
             interval(c.ci_low, c.ci_high),
             std::to_string(c.participants.size()) + ": " +
                 interval(c.participant_ci_low, c.participant_ci_high),
             c.target_value ? format_short(c.target_value)
                            : std::string("no physical value"),
             cell(c.bias), interval(c.bias_ci_low, c.bias_ci_high), c.constancy_text});
        csv_row(csv, {c.block, c.target, c.match, c.knob, "(all)", std::to_string(c.n),
                      full(c.mean), full(c.sd), c.on_log10 ? "log10" : "linear",
                      full(c.ci_low), full(c.ci_high), full(c.target_value), full(c.bias),
                      full(c.bias_ci_low), full(c.bias_ci_high), full(c.constancy),
                      c.constancy_factor});
        for (const ParticipantMatch& p : c.participants)
            csv_row(csv, {c.block, c.target, c.match, c.knob, p.participant,
                          std::to_string(p.n), format_full(p.mean), "", "", "", "",
                          full(c.target_value),
                          c.target_value ? format_full(p.mean - *c.target_value) : "", "",
                          "", "", ""});
    }
    section.blocks.push_back({Block::kTable, "", t, {}});
    for (const ConditionMatch& c : matches)
        for (const std::string& n : c.notes)
            section.blocks.push_back(paragraph(c.block + ", " + c.target + ": " + n));
    for (const std::string& block : block_order) {
        const std::string file = plot_file_name("matching", block);
        Block plot{Block::kPlot, file, {}, {}};
        plot.svg = match_plot(block, by_block[block]);
        section.files.emplace_back(file, plot.svg);
        section.blocks.push_back(plot);
    }
    Table per{{"block", "target", "participant", "trials", "mean match", "bias"}, {}};
    for (const ConditionMatch& c : matches)
        for (const ParticipantMatch& p : c.participants)
            per.rows.push_back({c.block, c.target, p.participant, std::to_string(p.n),
                                format_short(p.mean),
                                c.target_value ? format_short(p.mean - *c.target_value)
                                               : std::string("-")});
    section.blocks.push_back(paragraph("Each participant's mean match:"));
    section.blocks.push_back({Block::kTable, "", per, {}});
    section.files.emplace_back("matching.csv", csv.str());
}

// A participant's tracks in one block: a panel per procedure, delta against trial.
std::string track_plot(
    const ThresholdAnalysis& a, const std::vector<std::size_t>& tracks,
    const std::map<std::string, const StandardThreshold*>& by_standard) {
    std::vector<common::PlotPanel> panels;
    for (std::size_t k : tracks) {
        const StaircaseTrack& t = a.tracks[k];
        common::PlotPanel p;
        p.title = t.label;
        p.x_label = "trial (filled: correct; ringed: reversal)";
        p.y_label = "delta";
        for (std::size_t i = 0; i < t.intensity.size(); ++i) {
            p.x.push_back(static_cast<double>(i + 1));
            p.y.push_back(t.intensity[i]);
            p.open_points.push_back(!t.correct[i]);
            p.ringed_points.push_back(t.reversal[i]);
        }
        p.x_axis.scale = common::AxisScale::linear;
        p.y_axis.scale = common::AxisScale::linear;
        const auto it = by_standard.find(t.standard);
        if (it != by_standard.end() && it->second->jnd && !t.intensity.empty()) {
            const double j = *it->second->jnd;
            p.series.push_back({"JND (fit)", {1.0, double(t.intensity.size())}, {j, j}});
            p.series_behind = true;
            p.main_label = "delta shown";
        }
        panels.push_back(std::move(p));
    }
    return common::figure_svg("", panels, {320, 260, 3});
}

// The proportions correct to draw: each delta's own when there are few, else the
// trials in kDisplayBins equal stretches of lo..hi, each at its trials' mean delta.
constexpr int kDisplayBins = 8;
std::vector<PsychometricBin> display_bins(const std::vector<PsychometricBin>& bins,
                                          double lo, double hi) {
    std::vector<PsychometricBin> out;
    if (static_cast<int>(bins.size()) <= kDisplayBins || !(hi > lo)) {
        for (const PsychometricBin& b : bins)
            if (b.n_trials > 0) out.push_back(b);
        return out;
    }
    std::vector<double> sum_x(kDisplayBins, 0.0);
    out.assign(kDisplayBins, {});
    for (const PsychometricBin& b : bins) {
        const int k = std::clamp(static_cast<int>((b.x - lo) / (hi - lo) * kDisplayBins),
                                 0, kDisplayBins - 1);
        sum_x[k] += b.x * b.n_trials;
        out[k].n_trials += b.n_trials;
        out[k].n_correct += b.n_correct;
    }
    std::vector<PsychometricBin> kept;
    for (int k = 0; k < kDisplayBins; ++k)
        if (out[k].n_trials > 0) {
            out[k].x = sum_x[k] / out[k].n_trials;
            kept.push_back(out[k]);
        }
    return kept;
}

// The fitted functions of a participant's standards in one block, over the proportions
// correct at each delta.
std::string fit_plot(const std::vector<const StandardThreshold*>& standards) {
    std::vector<common::PlotPanel> panels;
    for (const StandardThreshold* s : standards) {
        common::PlotPanel p;
        p.title = s->standard;
        p.x_label = "delta (n trials beside each dot; line: fit)";
        p.y_label = "proportion correct";
        p.join = false;
        p.fixed_y = common::fixed_axis(0.0, 1.0);
        p.x_axis.scale = common::AxisScale::linear;
        double lo = INFINITY, hi = -INFINITY;
        for (const PsychometricBin& b : s->fit.bins) {
            lo = std::min(lo, b.x);
            hi = std::max(hi, b.x);
        }
        for (const PsychometricBin& b : display_bins(s->fit.bins, lo, hi)) {
            p.x.push_back(b.x);
            p.y.push_back(static_cast<double>(b.n_correct) / b.n_trials);
            p.point_labels.push_back(std::to_string(b.n_trials));
        }
        if (s->fit.fitted && std::isfinite(lo) && hi > lo) {
            common::PlotSeries curve{"fitted psi", {}, {}};
            for (int i = 0; i <= 60; ++i) {
                const double x = lo + (hi - lo) * i / 60.0;
                const double y = psychometric_psi(s->fit, x);
                if (!std::isfinite(y)) continue;
                curve.x.push_back(x);
                curve.y.push_back(y);
            }
            p.series.push_back(std::move(curve));
            p.series_behind = true;
            p.main_label = "proportion correct";
        }
        panels.push_back(std::move(p));
    }
    return common::figure_svg("", panels, {320, 260, 3});
}

void add_thresholds(MatchingSection& section, const ThresholdAnalysis& a) {
    if (a.thresholds.empty()) return;
    std::ostringstream csv;
    csv_row(csv, {"participant",
                  "block",
                  "standard",
                  "knob",
                  "standard_value",
                  "guess",
                  "p_correct",
                  "trials",
                  "correct",
                  "jnd",
                  "jnd_text",
                  "jnd_ci_low",
                  "jnd_ci_high",
                  "weber",
                  "weber_ci_low",
                  "weber_ci_high",
                  "alpha",
                  "beta",
                  "lapse",
                  "slope",
                  "jnd_between_low",
                  "jnd_between_high",
                  "jnd_ci_text",
                  "weber_text",
                  "weber_ci_text",
                  "bootstrap_samples",
                  "bootstrap_below",
                  "bootstrap_above",
                  "nonzero_delta_trials",
                  "nonzero_delta_correct",
                  "all_nonzero_correct"});
    section.blocks.push_back(heading("Thresholds", 2));
    section.blocks.push_back(paragraph(
        "Per participant, block and standard, every trial of the standard's interleaved "
        "procedures is fitted by maximum likelihood with a psychometric function (guess "
        "rate 1/2 for a pair, 1/3 for an odd one out; the lapse rate free in [0, 0.06]). "
        "The just-noticeable difference (JND) is the delta where the fitted function is "
        "halfway between chance and perfect (75% correct for a pair, 66.7% for an odd "
        "one "
        "out), with a parametric-bootstrap 95% interval; the Weber fraction is the JND "
        "over the standard's value of the knob. Where the answers jump from chance to "
        "correct between two neighbouring deltas the slope is not identified: the JND is "
        "only said to lie between them, with no interval. A bootstrap resample whose JND "
        "falls outside the deltas shown counts only as below or above them; when more "
        "than the 2.5% the interval leaves out on a side do, that end is only \"< the "
        "smallest delta\" or \"> the largest\". Each procedure's own estimate (up/down: "
        "the mean of its last reversals; QUEST: its posterior quantile, at its own "
        "target performance) is the cross-check. Flagged: a participant right on every "
        "trial with a non-zero delta, on " +
        std::to_string(kAllCorrectFlagTrials) +
        " or more of them, as a script that reads the answer would be (an observer "
        "right 80% of the time near the threshold, where a staircase keeps its trials, "
        "does that with probability 0.8^20 = 0.012)."));
    Table t{{"participant", "block", "standard", "standard value", "trials",
             "proportion correct", "JND", "JND 95% interval", "Weber fraction",
             "procedures' own estimates", "flagged"},
            {}};
    for (const StandardThreshold& s : a.thresholds) {
        std::string estimates;
        for (std::size_t k : s.tracks)
            estimates += (estimates.empty() ? "" : "; ") + a.tracks[k].procedure + ": " +
                         a.tracks[k].estimate_text;
        const Threshold& th = s.fit.threshold_p ? *s.fit.threshold_p : s.fit.threshold;
        t.rows.push_back(
            {s.participant, s.block, s.standard, cell(s.standard_value),
             std::to_string(s.fit.trials),
             s.fit.trials > 0
                 ? format_short(static_cast<double>(s.fit.correct) / s.fit.trials)
                 : std::string("-"),
             s.jnd_text, s.jnd_ci_text.empty() ? std::string("-") : s.jnd_ci_text,
             s.weber_text.empty()
                 ? std::string("-")
                 : s.weber_text +
                       (s.weber_ci_text.empty() ? "" : " (" + s.weber_ci_text + ")"),
             estimates.empty() ? std::string("-") : estimates,
             s.all_nonzero_correct
                 ? "right on all " + std::to_string(s.nonzero_trials) + " non-zero deltas"
                 : std::string("-")});
        csv_row(csv, {s.participant,
                      s.block,
                      s.standard,
                      s.knob,
                      full(s.standard_value),
                      format_full(s.guess),
                      format_full(s.p_correct),
                      std::to_string(s.fit.trials),
                      std::to_string(s.fit.correct),
                      full(s.jnd),
                      s.jnd_text,
                      full(s.jnd_low),
                      full(s.jnd_high),
                      full(s.weber),
                      full(s.weber_low),
                      full(s.weber_high),
                      full(s.fit.alpha),
                      full(s.fit.beta),
                      full(s.fit.lapse),
                      full(th.slope),
                      full(s.jnd_between_low),
                      full(s.jnd_between_high),
                      s.jnd_ci_text,
                      s.weber_text,
                      s.weber_ci_text,
                      std::to_string(s.fit.bootstrap_samples),
                      std::to_string(th.bootstrap_below),
                      std::to_string(th.bootstrap_above),
                      std::to_string(s.nonzero_trials),
                      std::to_string(s.nonzero_correct),
                      s.all_nonzero_correct ? "yes" : "no"});
    }
    section.blocks.push_back({Block::kTable, "", t, {}});
    for (const StandardThreshold& s : a.thresholds) {
        const std::string who = s.participant + ", " + s.block + ", " + s.standard + ": ";
        for (const std::string& n : s.notes) section.blocks.push_back(paragraph(who + n));
        for (const std::string& n : s.fit.notes)
            section.blocks.push_back(paragraph(who + n));
    }
    Table fits{{"participant", "block", "standard", "alpha", "beta", "lapse",
                "slope at the JND", "deviance p", "bootstrap samples"},
               {}};
    for (const StandardThreshold& s : a.thresholds) {
        const Threshold& th = s.fit.threshold_p ? *s.fit.threshold_p : s.fit.threshold;
        fits.rows.push_back(
            {s.participant, s.block, s.standard, cell(s.fit.alpha), cell(s.fit.beta),
             cell(s.fit.lapse), cell(th.slope),
             s.fit.deviance_p ? format_p_short(s.fit.deviance_p) : std::string("-"),
             std::to_string(s.fit.bootstrap_samples)});
    }
    section.blocks.push_back(
        paragraph(std::string("The fits (") +
                  (a.thresholds.front().fit.family == PsychometricFamily::weibull
                       ? "Weibull: alpha its scale, beta its shape"
                       : "cumulative Gaussian: alpha its mean, beta its SD") +
                  "):"));
    section.blocks.push_back({Block::kTable, "", fits, {}});

    // The figures: per participant and block, the tracks and the fits.
    std::vector<std::pair<std::string, std::string>> groups;
    std::map<std::pair<std::string, std::string>, std::vector<const StandardThreshold*>>
        standards;
    for (const StandardThreshold& s : a.thresholds) {
        auto& list = standards[{s.participant, s.block}];
        if (list.empty()) groups.emplace_back(s.participant, s.block);
        list.push_back(&s);
    }
    for (const auto& g : groups) {
        const auto& list = standards[g];
        std::vector<std::size_t> tracks;
        std::map<std::string, const StandardThreshold*> by_standard;
        for (const StandardThreshold* s : list) {
            tracks.insert(tracks.end(), s->tracks.begin(), s->tracks.end());
            by_standard[s->standard] = s;
        }
        section.blocks.push_back(heading(g.first + ", " + g.second, 3));
        const std::string track_file = plot_file_name("staircase_" + g.first, g.second);
        Block plot{Block::kPlot, track_file, {}, {}};
        plot.svg = track_plot(a, tracks, by_standard);
        section.files.emplace_back(track_file, plot.svg);
        section.blocks.push_back(plot);
        const std::string fit_file = plot_file_name("psychometric_" + g.first, g.second);
        Block fit{Block::kPlot, fit_file, {}, {}};
        fit.svg = fit_plot(list);
        section.files.emplace_back(fit_file, fit.svg);
        section.blocks.push_back(fit);
        for (std::size_t k : tracks)
            for (const std::string& n : a.tracks[k].notes)
                if (n.rfind("Held", 0) != 0)  // said with the threshold already
                    section.blocks.push_back(paragraph(a.tracks[k].label + ": " + n));
    }
    section.files.emplace_back("thresholds.csv", csv.str());
}

}  // namespace

MatchingSection matching_section(const std::vector<ConditionMatch>& matches,
                                 const ThresholdAnalysis& thresholds) {
    MatchingSection section;
    add_matching(section, matches);
    add_thresholds(section, thresholds);
    return section;
}

}  // namespace lucent::analysis
