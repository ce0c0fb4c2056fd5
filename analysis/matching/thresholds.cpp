#include "analysis/matching/thresholds.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "analysis/matching/matching.h"
#include "analysis/report/format.h"
#include "study/adaptive/quest.h"
#include "study/adaptive/staircase.h"
#include "study/adaptive/staircase_block.h"

namespace lucent::analysis {
namespace {

std::string text(double v) { return format_short(v); }

const study::Block::Procedure* find_procedure(const study::Block& block,
                                              const std::string& id) {
    for (const auto& p : block.procedures)
        if (p.id == id) return &p;
    return nullptr;
}

// Replays a track through its procedure: reversals and the procedure's own estimate.
void replay(StaircaseTrack& track, const study::Block& block,
            const study::Block::Procedure& procedure, int last_reversals) {
    try {
        auto engine = study::adaptive::make_procedure(block, procedure);
        std::size_t replayed = 0;
        for (std::size_t i = 0; i < track.intensity.size(); ++i) {
            if (engine->finished()) {
                track.notes.push_back("Its procedure had finished after " +
                                      std::to_string(i) + " trials; the " +
                                      std::to_string(track.intensity.size() - i) +
                                      " after are not in its own estimate.");
                break;
            }
            engine->next();
            engine->add_response(track.correct[i], track.intensity[i]);
            ++replayed;
        }
        if (const auto* s =
                dynamic_cast<const study::adaptive::Staircase*>(engine.get())) {
            for (int r : s->reversal_trials())
                if (r >= 0 && static_cast<std::size_t>(r) < replayed)
                    track.reversal[static_cast<std::size_t>(r)] = true;
            const auto& ri = s->reversal_intensities();
            track.estimate = reversal_estimate(ri, last_reversals);
            if (track.estimate) {
                const int used =
                    std::min<int>(last_reversals, static_cast<int>(ri.size()));
                track.estimate_text = text(*track.estimate) + " (mean of the last " +
                                      std::to_string(used) + " of " +
                                      std::to_string(ri.size()) + " reversals)";
            } else {
                track.estimate_text = "no estimate: " + std::to_string(ri.size()) +
                                      " reversal" + (ri.size() == 1 ? "" : "s") +
                                      " (two are needed)";
            }
        } else if (const auto* q =
                       dynamic_cast<const study::adaptive::Quest*>(engine.get())) {
            const double v = q->quantile();
            if (std::isfinite(v)) {
                track.estimate = v;
                track.estimate_text = text(v) + " (QUEST's posterior quantile, at " +
                                      text(100.0 * procedure.p_threshold) + "% correct)";
            } else {
                track.estimate_text = "no estimate: QUEST's posterior is undefined";
            }
        }
    } catch (const std::exception& e) {
        track.estimate_text = "no estimate: the stored trials do not replay (" +
                              std::string(e.what()) + ")";
    }
}

// The Weber fraction, JND / the standard's value, and its interval, in numbers and words;
// never a non-positive one.
void weber_of(StandardThreshold& s, const Threshold& t) {
    if (!s.standard_value) return;
    const double sv = *s.standard_value;
    const bool has_jnd = t.status != ThresholdStatus::not_identified;
    if (!(sv > 0)) {
        if (has_jnd)
            s.notes.push_back("No Weber fraction: the standard's " + s.knob + " is " +
                              text(sv) + ", not positive.");
        return;
    }
    const auto positive = [](std::optional<double> v) { return v && *v > 0; };
    switch (t.status) {
        case ThresholdStatus::estimated:
            if (!positive(s.jnd)) {
                s.notes.push_back("No Weber fraction: the JND, " + s.jnd_text +
                                  ", is not positive.");
                return;
            }
            s.weber = *s.jnd / sv;
            s.weber_text = text(*s.weber);
            break;
        case ThresholdStatus::below_range:
            if (positive(t.bound)) s.weber_text = "< " + text(*t.bound / sv);
            return;
        case ThresholdStatus::above_range:
            if (positive(t.bound)) s.weber_text = "> " + text(*t.bound / sv);
            return;
        case ThresholdStatus::between:
            if (t.between_low && *t.between_low >= 0 && positive(t.between_high))
                s.weber_text = "between " + text(*t.between_low / sv) + " and " +
                               text(*t.between_high / sv);
            return;
        case ThresholdStatus::not_identified:
            return;
    }
    // The interval's ends: a number, or "< smallest delta / standard" or "> largest".
    if (t.ci_low_status == ThresholdStatus::not_identified ||
        t.ci_high_status == ThresholdStatus::not_identified || s.fit.bins.empty())
        return;
    const double x_min = s.fit.bins.front().x, x_max = s.fit.bins.back().x;
    const auto end = [&](ThresholdStatus status, std::optional<double> value,
                         std::optional<double>& weber) -> std::optional<std::string> {
        if (status == ThresholdStatus::estimated && positive(value)) {
            weber = *value / sv;
            return text(*weber);
        }
        if (status == ThresholdStatus::below_range && x_min > 0)
            return "< " + text(x_min / sv);
        if (status == ThresholdStatus::above_range && x_max > 0)
            return "> " + text(x_max / sv);
        return std::nullopt;
    };
    const auto low = end(t.ci_low_status, t.ci_low, s.weber_low);
    const auto high = end(t.ci_high_status, t.ci_high, s.weber_high);
    if (low && high) {
        s.weber_ci_text = *low + " .. " + *high;
    } else {
        s.weber_low.reset();
        s.weber_high.reset();
        s.notes.push_back("No interval of the Weber fraction: the JND's interval, " +
                          t.ci_text + ", reaches a delta that is not positive.");
    }
}

// Right on every trial with a non-zero delta, on enough of them to be suspicious.
void flag_all_correct(StandardThreshold& s,
                      const std::vector<PsychometricTrial>& trials) {
    double scale = 1.0;
    for (const PsychometricTrial& t : trials) scale = std::max(scale, std::abs(t.x));
    for (const PsychometricTrial& t : trials) {
        if (!(std::abs(t.x) > 1e-9 * scale)) continue;  // a delta of 0: a guess
        ++s.nonzero_trials;
        if (t.correct) ++s.nonzero_correct;
    }
    s.all_nonzero_correct = s.nonzero_trials >= kAllCorrectFlagTrials &&
                            s.nonzero_correct == s.nonzero_trials;
    if (s.all_nonzero_correct)
        s.notes.push_back(
            "Flagged: right on every one of the " + std::to_string(s.nonzero_trials) +
            " trials with a non-zero delta, as a script that reads the answer would be "
            "(flagged from " +
            std::to_string(kAllCorrectFlagTrials) +
            " such trials: a staircase keeps its trials near the threshold, where an "
            "observer right 80% of the time is right on 20 in a row with probability "
            "0.8^20 = 0.012). Check the sessions before keeping them; an observer whose "
            "JND is below the smallest delta shown would be right on them too.");
}

}  // namespace

std::optional<double> reversal_estimate(const std::vector<double>& reversal_intensities,
                                        int last) {
    if (reversal_intensities.size() < 2 || last < 2) return std::nullopt;
    const std::size_t k = std::min<std::size_t>(last, reversal_intensities.size());
    double sum = 0;
    for (std::size_t i = reversal_intensities.size() - k; i < reversal_intensities.size();
         ++i)
        sum += reversal_intensities[i];
    const double v = sum / static_cast<double>(k);
    if (!std::isfinite(v)) return std::nullopt;
    return v;
}

ThresholdAnalysis analyse_thresholds(const std::vector<StaircaseRow>& rows,
                                     const study::Protocol* protocol,
                                     const ThresholdOptions& options) {
    ThresholdAnalysis out;
    // Tracks by (session, label), in order of first appearance; trials by position.
    std::vector<const StaircaseRow*> sorted;
    for (const StaircaseRow& r : rows) sorted.push_back(&r);
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const StaircaseRow* a, const StaircaseRow* b) {
                         if (a->participant != b->participant)
                             return a->participant < b->participant;
                         if (a->session != b->session) return a->session < b->session;
                         return a->trial < b->trial;
                     });
    std::map<std::pair<std::string, std::string>, std::size_t> track_of;
    using Key = std::tuple<std::string, std::string, std::string>;
    std::map<Key, std::size_t> threshold_of;
    std::map<Key, std::vector<PsychometricTrial>> trials;
    for (const StaircaseRow* r : sorted) {
        auto [it, added] = track_of.try_emplace(
            {r->session, r->block + "\x1f" + r->staircase}, out.tracks.size());
        if (added) {
            StaircaseTrack t;
            t.participant = r->participant;
            t.session = r->session;
            t.block = r->block;
            t.standard = r->standard;
            t.label = r->staircase;
            const std::size_t slash = r->staircase.rfind('/');
            t.procedure = slash == std::string::npos ? r->staircase
                                                     : r->staircase.substr(slash + 1);
            out.tracks.push_back(t);
        }
        StaircaseTrack& t = out.tracks[it->second];
        t.intensity.push_back(r->intensity);
        t.correct.push_back(r->correct);
        t.reversal.push_back(false);
        const Key key{r->participant, r->block, r->standard};
        auto [th, new_threshold] = threshold_of.try_emplace(key, out.thresholds.size());
        if (new_threshold) {
            StandardThreshold s;
            s.participant = r->participant;
            s.block = r->block;
            s.standard = r->standard;
            out.thresholds.push_back(s);
        }
        if (added) out.thresholds[th->second].tracks.push_back(it->second);
        trials[key].push_back({r->intensity, r->correct});
    }

    // Each track: its procedure's bounds, replay and estimate.
    for (StaircaseTrack& t : out.tracks) {
        const study::Block* block = protocol ? protocol->find_block(t.block) : nullptr;
        const study::Block::Procedure* procedure =
            block ? find_procedure(*block, t.procedure) : nullptr;
        if (!procedure) {
            t.estimate_text = "no estimate: the procedure '" + t.label +
                              "' is not in the stored protocol";
            continue;
        }
        t.method = procedure->method;
        t.max_delta = procedure->max_delta;
        t.min_delta = procedure->min_delta;
        const double tol = 1e-9 * std::max(1.0, std::abs(t.max_delta));
        for (double x : t.intensity) {
            if (x >= t.max_delta - tol) ++t.at_max;
            if (x <= t.min_delta + tol) ++t.at_min;
        }
        t.held_at_max = t.at_max >= 2;
        if (t.held_at_max)
            t.notes.push_back("Held at the largest delta the block allows, " +
                              text(t.max_delta) + ", on " + std::to_string(t.at_max) +
                              " trials: the knob's range limits this staircase; the "
                              "threshold may lie beyond the range.");
        if (t.at_min >= 2)
            t.notes.push_back("At the smallest delta the block allows, " +
                              text(t.min_delta) + ", on " + std::to_string(t.at_min) +
                              " trials: the staircase could go no lower.");
        replay(t, *block, *procedure, options.last_reversals);
    }

    // Each participant x block x standard: the fit.
    for (StandardThreshold& s : out.thresholds) {
        const study::Block* block = protocol ? protocol->find_block(s.block) : nullptr;
        if (block) {
            s.guess = study::adaptive::guess_rate(*block);
            s.knob = block->knob;
            if (protocol) s.standard_value = knob_value(*protocol, s.standard, s.knob);
        } else {
            s.notes.push_back(
                "The block is not in the stored protocol: a pair's guess rate, 1/2, is "
                "assumed.");
        }
        s.p_correct = (1.0 + s.guess) / 2.0;
        std::vector<PsychometricTrial> data =
            trials[{s.participant, s.block, s.standard}];
        if (options.family == PsychometricFamily::weibull) {
            const std::size_t before = data.size();
            data.erase(
                std::remove_if(data.begin(), data.end(),
                               [](const PsychometricTrial& t) { return !(t.x > 0); }),
                data.end());
            if (data.size() < before)
                s.notes.push_back(std::to_string(before - data.size()) +
                                  " trials at a delta of 0 or less are left out of the "
                                  "Weibull fit (it needs positive deltas).");
        }
        PsychometricOptions po;
        po.family = options.family;
        po.guess = s.guess;
        po.free_lapse = true;
        po.p_correct_level = s.p_correct;
        po.bootstrap = options.bootstrap;
        po.seed = options.seed;
        s.fit = fit_psychometric(data, po);
        const Threshold& t = s.fit.threshold_p ? *s.fit.threshold_p : s.fit.threshold;
        const std::string level = text(100.0 * s.p_correct) + "% correct";
        switch (t.status) {
            case ThresholdStatus::estimated:
                s.jnd = t.value;
                s.jnd_low = t.ci_low;
                s.jnd_high = t.ci_high;
                s.jnd_text = text(*t.value);
                s.jnd_ci_text = t.ci_text;
                break;
            case ThresholdStatus::below_range:
                s.jnd_text = "< " + text(t.bound.value_or(0.0));
                s.notes.push_back("The JND (" + level +
                                  ") is below the smallest delta shown, " +
                                  text(t.bound.value_or(0.0)) + ".");
                break;
            case ThresholdStatus::above_range:
                s.jnd_text = "> " + text(t.bound.value_or(0.0));
                s.notes.push_back("The JND (" + level +
                                  ") is above the largest delta shown, " +
                                  text(t.bound.value_or(0.0)) + ".");
                break;
            case ThresholdStatus::between:
                s.jnd_between_low = t.between_low;
                s.jnd_between_high = t.between_high;
                s.jnd_text = t.text;
                s.notes.push_back(
                    "The JND (" + level + ") lies somewhere between the deltas " +
                    text(t.between_low.value_or(0.0)) + " and " +
                    text(t.between_high.value_or(0.0)) +
                    ": the answers jump from chance to correct between "
                    "these two deltas shown, so the slope is not identified "
                    "and no JND value or interval is given.");
                break;
            case ThresholdStatus::not_identified:
                s.jnd_text = "no threshold";
                s.notes.push_back(
                    "No threshold: the answers do not rise with the delta (see the "
                    "fit's note).");
                break;
        }
        for (std::size_t k : s.tracks)
            for (const std::string& n : out.tracks[k].notes)
                if (out.tracks[k].held_at_max && n.rfind("Held", 0) == 0)
                    s.notes.push_back(out.tracks[k].label + ": " + n);
        weber_of(s, t);
        flag_all_correct(s, trials[{s.participant, s.block, s.standard}]);
    }
    return out;
}

}  // namespace lucent::analysis
