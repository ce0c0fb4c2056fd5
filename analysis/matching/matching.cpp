#include "analysis/matching/matching.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <map>
#include <variant>

#include "analysis/report/format.h"
#include "renderer/core/common_knobs.h"
#include "renderer/techniques/registry.h"

namespace lucent::analysis {
namespace {

std::string text(double v) { return format_short(v); }

// The target's value of the knob, or why it has none.
std::optional<double> target_value(const study::Protocol& protocol,
                                   const Stimulus& target, const Stimulus* match,
                                   const std::string& knob, std::string& why) {
    if (!target.live()) {
        why = "no physical value: the target is a picture";
        return std::nullopt;
    }
    if (!match || match->technique != target.technique) {
        why = "no physical value: the target is rendered by " + target.technique +
              (match ? ", the match by " + match->technique : std::string()) +
              ", whose knob '" + knob + "' is not the target's";
        return std::nullopt;
    }
    if (const auto v = knob_value(protocol, target.id, knob)) return v;
    why = "no physical value: the target states no number for '" + knob + "'";
    return std::nullopt;
}

}  // namespace

std::optional<double> knob_value(const study::Protocol& protocol,
                                 const std::string& stimulus, const std::string& knob) {
    const Stimulus* s = protocol.find_stimulus(stimulus);
    if (!s || !s->live()) return std::nullopt;
    if (const auto v = protocol.numeric_parameter(stimulus, knob)) return v;
    // Not stated: the technique's default, which the renderer used.
    try {
        for (const Knob& k : knobs_for(find_technique(s->technique)))
            if (k.name == knob)
                if (const double* d = std::get_if<double>(&k.default_value)) return *d;
    } catch (const std::exception&) {
    }
    return std::nullopt;
}

MeanInterval mean_interval(const std::vector<double>& values, double level) {
    MeanInterval out;
    if (values.empty()) return out;
    const double shift = values.front();
    double sum = 0;
    for (double v : values) sum += v - shift;
    const double n = static_cast<double>(values.size());
    const double mean = shift + sum / n;
    out.mean = mean;
    if (values.size() < 2) return out;
    double squares = 0;
    for (double v : values) squares += (v - mean) * (v - mean);
    const double sd = std::sqrt(squares / (n - 1));
    out.sd = sd;
    const boost::math::students_t t(n - 1);
    const double half = boost::math::quantile(t, 0.5 + 0.5 * level) * sd / std::sqrt(n);
    out.low = mean - half;
    out.high = mean + half;
    return out;
}

std::optional<double> constancy_index(double mean_match, double target, double lo,
                                      double hi, bool log_scale) {
    if (log_scale) {
        if (!(mean_match > 0 && target > 0 && lo > 0 && hi > 0)) return std::nullopt;
        mean_match = std::log10(mean_match);
        target = std::log10(target);
        lo = std::log10(lo);
        hi = std::log10(hi);
    }
    const double room = std::max(target - lo, hi - target);
    if (!(room > 0) || !std::isfinite(room)) return std::nullopt;
    const double index = 1.0 - std::abs(mean_match - target) / room;
    if (!std::isfinite(index)) return std::nullopt;
    return index;
}

std::vector<std::string> differing_factors(const Stimulus& a, const Stimulus& b,
                                           const std::string& knob) {
    std::vector<std::string> out;
    if (a.mesh != b.mesh) out.push_back("mesh");
    // Across techniques only the scene's knobs (light, camera, background) are factors:
    // each technique's own knobs describe the material being matched.
    const bool same_technique = a.technique == b.technique;
    auto is_factor = [&](const std::string& name) {
        if (name == knob) return false;
        if (same_technique) return true;
        for (const Knob& k : scene_knobs())
            if (k.name == name) return true;
        return false;
    };
    std::map<std::string, std::pair<std::string, std::string>> all;
    for (const auto& [k, v] : a.parameters) all[k].first = v;
    for (const auto& [k, v] : b.parameters) all[k].second = v;
    for (const auto& [k, v] : all)
        if (is_factor(k) && v.first != v.second) out.push_back(k);
    return out;
}

std::vector<ConditionMatch> analyse_matches(const std::vector<MatchRow>& rows,
                                            const study::Protocol* protocol,
                                            const MatchingOptions& options) {
    std::vector<ConditionMatch> out;
    std::map<std::pair<std::string, std::string>, std::vector<const MatchRow*>> by;
    for (const MatchRow& r : rows) {
        auto& list = by[{r.block, r.target}];
        if (list.empty()) {
            ConditionMatch c;
            c.block = r.block;
            c.target = r.target;
            c.match = r.match;
            c.knob = r.knob;
            out.push_back(c);
        }
        list.push_back(&r);
    }
    for (ConditionMatch& c : out) {
        const auto& list = by[{c.block, c.target}];
        const study::Block* block = protocol ? protocol->find_block(c.block) : nullptr;
        if (block) {
            c.range_min = block->range_min;
            c.range_max = block->range_max;
            c.log_scale = block->scale == "log";
            if (c.match.empty()) c.match = block->match;
            if (c.knob.empty()) c.knob = block->knob;
        }
        std::vector<double> values;
        std::map<std::string, std::vector<double>> per;
        for (const MatchRow* r : list) {
            values.push_back(r->final_value);
            auto [it, added] = per.try_emplace(r->participant);
            if (added) c.participants.push_back({r->participant, 0, 0});
            it->second.push_back(r->final_value);
        }
        c.n = static_cast<int>(values.size());
        // A log block's matches are averaged on log10 (a geometric mean; its interval
        // back-transformed, its SD in log10 units), as the participant turned the knob.
        const bool all_positive =
            std::all_of(values.begin(), values.end(), [](double v) { return v > 0; });
        c.on_log10 = c.log_scale && all_positive;
        if (c.log_scale && !all_positive)
            c.notes.push_back(
                "A match of 0 or less on a log block: the statistics are on the knob's "
                "own "
                "scale.");
        auto scaled = [&](std::vector<double> v) {
            if (c.on_log10)
                for (double& x : v) x = std::log10(x);
            return v;
        };
        auto back = [&](const std::optional<double>& v) -> std::optional<double> {
            if (!v || !c.on_log10) return v;
            const double x = std::pow(10.0, *v);
            if (!std::isfinite(x)) return std::nullopt;
            return x;
        };
        const MeanInterval m = mean_interval(scaled(values), options.level);
        c.mean = back(m.mean);
        c.sd = m.sd;
        c.ci_low = back(m.low);
        c.ci_high = back(m.high);
        std::vector<double> means;
        for (ParticipantMatch& p : c.participants) {
            const auto& v = per[p.participant];
            p.n = static_cast<int>(v.size());
            p.mean = back(mean_interval(scaled(v)).mean).value_or(0.0);
            means.push_back(p.mean);
        }
        if (means.size() >= 2) {
            const MeanInterval pm = mean_interval(scaled(means), options.level);
            c.participant_mean = back(pm.mean);
            c.participant_sd = pm.sd;
            c.participant_ci_low = back(pm.low);
            c.participant_ci_high = back(pm.high);
        }
        if (c.n == 1)
            c.notes.push_back("One match only: no SD and no interval.");
        else if (c.sd && *c.sd == 0.0)
            c.notes.push_back("Every match was the same value, " + text(*c.mean) +
                              ": the SD is 0 and the interval a single point.");
        if (block && c.n > 0) {
            const double span = c.range_max - c.range_min;
            const double tol = 1e-9 * std::max(1.0, std::abs(span));
            const bool all_min = std::all_of(values.begin(), values.end(), [&](double v) {
                return std::abs(v - c.range_min) <= tol;
            });
            const bool all_max = std::all_of(values.begin(), values.end(), [&](double v) {
                return std::abs(v - c.range_max) <= tol;
            });
            if (all_min || all_max) {
                c.all_at_range_end = true;
                c.notes.push_back(
                    std::string("Every match is at the range's ") +
                    (all_min ? "lower end, " + text(c.range_min)
                             : "upper end, " + text(c.range_max)) +
                    ": the range did not reach the value that matches (the mean and the "
                    "bias are bounds, not estimates).");
            } else {
                int at_end = 0;
                for (double v : values)
                    if (std::abs(v - c.range_min) <= tol ||
                        std::abs(v - c.range_max) <= tol)
                        ++at_end;
                if (at_end > 0)
                    c.notes.push_back(std::to_string(at_end) + " of " +
                                      std::to_string(c.n) +
                                      " matches at an end of the range " +
                                      text(c.range_min) + ".." + text(c.range_max) + ".");
            }
        }
        // The target's value and the constancy index.
        const Stimulus* target = protocol ? protocol->find_stimulus(c.target) : nullptr;
        const Stimulus* match = protocol ? protocol->find_stimulus(c.match) : nullptr;
        std::string why = "no physical value: the stored protocol is not readable";
        if (target && protocol)
            c.target_value = target_value(*protocol, *target, match, c.knob, why);
        if (c.target_value && c.mean) {
            c.bias = *c.mean - *c.target_value;
            if (c.ci_low && c.ci_high) {
                c.bias_ci_low = *c.ci_low - *c.target_value;
                c.bias_ci_high = *c.ci_high - *c.target_value;
            }
        }
        c.picture_target = target && !target->live();
        if (target && match && !c.picture_target) {
            c.factors = differing_factors(*target, *match, c.knob);
            c.factors_known = true;
        }
        c.no_value_reason = why;
    }
    // The constancy index: against the target's own value, else against its match in a
    // block where the target and the match share every scene factor.
    for (ConditionMatch& c : out) {
        if (c.picture_target) {
            c.constancy_text = "no constancy index: the target is a picture";
            continue;
        }
        if (!c.factors_known) {
            c.constancy_text =
                "no constancy index: the target or the match is not a live "
                "stimulus of the stored protocol";
            continue;
        }
        if (c.factors.empty()) {
            c.constancy_text =
                "no constancy index: the target and the match share every scene factor " +
                std::string(c.target_value
                                ? "(a same-scene match measures accuracy: see the bias)"
                                : "(the same-scene match other conditions are compared "
                                  "with)");
            continue;
        }
        if (c.factors.size() > 1) {
            std::string list;
            for (const auto& f : c.factors) list += (list.empty() ? "" : ", ") + f;
            c.constancy_text = "no constancy index: the target and the match differ in " +
                               std::to_string(c.factors.size()) + " scene factors (" +
                               list + "), not one";
            continue;
        }
        if (!c.mean) {
            c.constancy_text = "no constancy index: no matches";
            continue;
        }
        std::optional<double> reference = c.target_value;
        std::string against = "the target's own value";
        if (!reference)
            for (const ConditionMatch& o : out)
                if (&o != &c && o.target == c.target && o.knob == c.knob &&
                    o.factors_known && o.factors.empty() && o.mean) {
                    reference = o.mean;
                    against =
                        "the same-scene match in block " + o.block + ", " + text(*o.mean);
                    break;
                }
        if (!reference) {
            c.constancy_text = "no constancy index: " + c.no_value_reason +
                               ", and no block matches this target in the same scene";
            continue;
        }
        c.constancy_factor = c.factors.front();
        c.constancy_reference = reference;
        c.constancy =
            constancy_index(*c.mean, *reference, c.range_min, c.range_max, c.log_scale);
        if (c.constancy)
            c.constancy_text = text(*c.constancy) + " across " + c.constancy_factor +
                               " (against " + against + ")";
        else
            c.constancy_text =
                "no constancy index: the range leaves no room around the reference" +
                std::string(c.log_scale ? " (or a value is not positive on the log scale)"
                                        : "");
    }
    return out;
}

}  // namespace lucent::analysis
