#include "study/web_series.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <variant>

#include "common/number_text.h"
#include "renderer/techniques/registry.h"

namespace lucent::study {

const KnobSeries* WebSeries::find(std::string_view block,
                                  std::string_view stimulus) const {
    for (const KnobSeries& s : series)
        if (s.block == block && s.stimulus == stimulus) return &s;
    return nullptr;
}

double stimulus_knob_value(const Protocol& protocol, std::string_view stimulus,
                           const std::string& knob) {
    if (const std::optional<double> v = protocol.numeric_parameter(stimulus, knob))
        return *v;
    const Stimulus* s = protocol.find_stimulus(stimulus);
    const std::vector<Knob> knobs = knobs_for(find_technique(s->technique));
    return std::get<double>(find_knob(knobs, knob)->default_value);
}

std::vector<double> adjust_series_values(const Block& block) {
    const bool log = block.scale == "log";
    const double low = log ? std::log10(block.range_min) : block.range_min;
    const double high = log ? std::log10(block.range_max) : block.range_max;
    const int n = std::max(2, block.series_steps);
    std::vector<double> values;
    values.reserve(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        // The ends exactly, whatever log10 and pow round to (as AdjustInput's).
        if (i == 0) {
            values.push_back(block.range_min);
            continue;
        }
        if (i == n - 1) {
            values.push_back(block.range_max);
            continue;
        }
        const double position = low + (high - low) * i / (n - 1);
        values.push_back(
            log ? std::clamp(std::pow(10.0, position), block.range_min, block.range_max)
                : position);
    }
    return values;
}

std::vector<double> ladder_deltas(const Block& block) {
    double low = block.procedures.front().min_delta;
    double high = block.procedures.front().max_delta;
    for (const Block::Procedure& p : block.procedures) {
        low = std::min(low, p.min_delta);
        high = std::max(high, p.max_delta);
    }
    std::vector<double> deltas;
    const double step = block.ladder_step;
    // Rungs k * step; a relative slack so that max_delta = 16 with step 1 is a rung.
    const auto first = static_cast<long>(std::ceil(low / step - 1e-9));
    const auto last = static_cast<long>(std::floor(high / step + 1e-9));
    for (long k = first; k <= last; ++k) deltas.push_back(static_cast<double>(k) * step);
    return deltas;
}

size_t nearest_step(const std::vector<double>& steps, double value) {
    const auto above = std::lower_bound(steps.begin(), steps.end(), value);
    if (above == steps.begin()) return 0;
    if (above == steps.end()) return steps.size() - 1;
    const auto below = above - 1;
    return static_cast<size_t>(value - *below <= *above - value ? below - steps.begin()
                                                                : above - steps.begin());
}

std::string series_picture_id(std::string_view stimulus, std::string_view knob,
                              double value) {
    return std::string(stimulus) + "@" + std::string(knob) + "=" +
           common::shortest_text(value);
}

namespace {

// A numeric start is shown in the browser as it is planned only if it is a point of the
// series ("random", "min" and "max" always are).
void check_start_in_series(const Protocol& protocol, const Block& block,
                           const std::vector<double>& steps) {
    if (block.start == "random" || block.start == "min" || block.start == "max") return;
    const double start = std::stod(block.start);
    const double nearest = steps[nearest_step(steps, start)];
    if (std::abs(nearest - start) <= 1e-12 * std::max(1.0, std::abs(start))) return;
    throw ProtocolError(protocol.source + ": block '" + block.id + "': start " +
                        block.start + " is not one of the browser's " +
                        std::to_string(steps.size()) +
                        " series values (nearest: " + common::shortest_text(nearest) +
                        "); change series_steps or the start");
}

// Each rung is a picture per standard, rendered and held in memory by `lucent serve`.
constexpr double kMaxRungs = 2000;

void check_ladder_size(const Protocol& protocol, const Block& block) {
    double low = block.procedures.front().min_delta;
    double high = block.procedures.front().max_delta;
    for (const Block::Procedure& p : block.procedures) {
        low = std::min(low, p.min_delta);
        high = std::max(high, p.max_delta);
    }
    const double rungs = std::floor((high - low) / block.ladder_step) + 1;
    if (rungs <= kMaxRungs) return;
    throw ProtocolError(
        protocol.source + ": block '" + block.id + "': the browser's ladder of deltas [" +
        common::shortest_text(low) + ", " + common::shortest_text(high) +
        "] in steps of " + common::shortest_text(block.ladder_step) + " would be " +
        common::shortest_text(rungs) + " pictures per standard (at most " +
        common::shortest_text(kMaxRungs) + "): set ladder_step or max_delta");
}

}  // namespace

WebSeries web_series(const Protocol& protocol) {
    WebSeries out;
    // A picture that is already a stimulus (or another series's) is shown by that id:
    // r = 30 - 5 is the standard r = 25 itself.
    std::map<std::string, std::string> id_of_picture;
    std::set<std::string> ids;
    for (const Stimulus& s : protocol.stimuli) {
        ids.insert(s.id);
        if (s.live()) id_of_picture.emplace(Protocol::picture_key(s), s.id);
    }
    const auto add = [&](const Block& block, const std::string& stimulus,
                         std::vector<double> steps, double base, double sign) {
        KnobSeries series{block.id, stimulus, block.knob, std::move(steps), {}};
        const Stimulus& spec = *protocol.find_stimulus(stimulus);
        for (double step : series.steps) {
            if (block.task == Task::staircase && step == 0) {
                series.pictures.push_back(stimulus);
                continue;
            }
            const double value = base + sign * step;
            Stimulus picture = spec;
            picture.parameters[block.knob] = common::shortest_text(value);
            auto [known, is_new] =
                id_of_picture.emplace(Protocol::picture_key(picture), "");
            if (is_new) {
                picture.id = series_picture_id(stimulus, block.knob, value);
                if (!ids.insert(picture.id).second)
                    throw ProtocolError(protocol.source + ": block '" + block.id +
                                        "': the series picture '" + picture.id +
                                        "' is also a protocol stimulus's id");
                known->second = picture.id;
                out.added.push_back(std::move(picture));
            }
            series.pictures.push_back(known->second);
        }
        out.series.push_back(std::move(series));
    };
    for (const Block& b : protocol.blocks) {
        if (b.task == Task::adjust) {
            add(b, b.match, adjust_series_values(b), 0, 1);
            check_start_in_series(protocol, b, out.series.back().steps);
        }
        if (b.task != Task::staircase) continue;
        for (const std::string& standard : b.stimuli) {
            check_ladder_size(protocol, b);
            add(b, standard, ladder_deltas(b),
                stimulus_knob_value(protocol, standard, b.knob),
                b.direction == "down" ? -1 : 1);
        }
    }
    return out;
}

Protocol with_series_pictures(const Protocol& protocol, const WebSeries& series) {
    Protocol out = protocol;
    out.stimuli.insert(out.stimuli.end(), series.added.begin(), series.added.end());
    return out;
}

}  // namespace lucent::study
