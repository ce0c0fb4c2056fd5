#include "study/trials/adjust/adjust_trials.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/number_text.h"
#include "common/observation_table.h"
#include "common/portable_random.h"
#include "study/store_rules.h"
#include "study/trials/block_keys.h"
#include "study/trials/table_reader.h"
#include "study/web_series.h"

namespace lucent::study {

using common::uniform_unit;

namespace {

// The keys of an adjust block (design notes: Block in protocol.h).
void read_adjust_block(const Protocol& p, TableReader& r, Block& b) {
    read_block_question(p, r, b);
    b.match = r.string("match", "", true);
    check_stimulus_ref(p, r, "match", b.match);
    b.knob = r.string("knob", "", true);
    const Knob knob = block_knob(p, r, b, b.match, "match");
    b.range_min = knob.min;
    b.range_max = knob.max;
    if (const toml::node* range = r.get("range")) {
        const toml::array* a = range->as_array();
        const bool numbers =
            a && a->size() == 2 && std::all_of(a->begin(), a->end(), [](auto& n) {
                return n.is_integer() || n.is_floating_point();
            });
        if (!numbers) r.fail(range, "range", "must be [min, max], two numbers");
        b.range_min = *(*a)[0].value<double>();
        b.range_max = *(*a)[1].value<double>();
        if (!(b.range_min < b.range_max) || b.range_min < knob.min ||
            b.range_max > knob.max)
            r.fail(range, "range",
                   "must be [min, max] with min < max inside the knob's range [" +
                       common::shortest_text(knob.min) + ", " +
                       common::shortest_text(knob.max) + "]");
    }
    b.scale = r.string("scale", "linear");
    if (b.scale != "linear" && b.scale != "log")
        r.fail(r.raw().get("scale"), "scale",
               "must be \"linear\" or \"log\", got '" + b.scale + "'");
    if (b.scale == "log" && !(b.range_min > 0))
        r.fail(r.raw().get("scale"), "scale",
               "a log scale needs a range above 0, got min " +
                   common::shortest_text(b.range_min));
    // Default steps: 1/20 and 1/200 of the range on the scale (a log step is in log10
    // units, a factor 10^step).
    const double width = b.scale == "log" ? std::log10(b.range_max / b.range_min)
                                          : b.range_max - b.range_min;
    b.step = r.number("step", width / 20, 0, width);
    if (!(b.step > 0)) r.fail(r.raw().get("step"), "step", "must be above 0");
    b.fine_step = r.number("fine_step", b.step / 10, 0, b.step);
    if (!(b.fine_step > 0))
        r.fail(r.raw().get("fine_step"), "fine_step", "must be above 0");
    b.series_steps = r.integer(
        "series_steps",
        static_cast<int>(std::min(10000.0, std::round(width / b.fine_step))) + 1, 2,
        10001);
    b.start = "random";
    if (const toml::node* start = r.get("start")) {
        if (start->is_string()) {
            b.start = *start->value<std::string>();
            if (b.start != "random" && b.start != "min" && b.start != "max")
                r.fail(start, "start",
                       "must be \"random\", \"min\", \"max\" or a number, got '" +
                           b.start + "'");
        } else {
            const double v = r.number("start", 0, b.range_min, b.range_max);
            b.start = common::shortest_text(v);
        }
    }
    for (const std::string& target : b.stimuli)
        if (target == b.match)
            r.fail(r.raw().get("match"), "match",
                   "'" + b.match + "' is also a target of block '" + b.id + "'");
}

class AdjustKind : public TrialKind {
public:
    const char* name() const override { return "adjust"; }
    bool is_choice() const override { return false; }
    bool is_scaling() const override { return false; }
    int pictures_per_trial() const override { return 2; }  // the target and the match
    int answers(const Block&) const override { return 1; }
    TrialScreen screen() const override { return TrialScreen::adjust; }
    const char* analysed_as() const override { return "matches"; }
    void read_block(const Protocol& p, TableReader& keys, Block& b) const override {
        read_adjust_block(p, keys, b);
    }
    std::vector<PlannedTrial> plan_block(const Protocol&, const Block& block,
                                         std::mt19937_64& rng) const override {
        return adjust_block_trials(block, rng);
    }
    // A finite final value, and each change on the way: finite, of a known input, in
    // time order (none when the start was confirmed as it was).
    void check_outcome(const std::string& where, const TrialAnswerFacts& facts,
                       const TrialOutcome& outcome) const override {
        if (!outcome.final_value)
            throw StoreError(where + " is an adjust trial without a final value");
        if (!std::isfinite(*outcome.final_value))
            throw StoreError(where + " has a final value that is not finite");
        for (size_t k = 0; k < outcome.adjustments.size(); ++k) {
            const Adjustment& a = outcome.adjustments[k];
            const std::string step = where + ": adjustment " + std::to_string(k + 1);
            if (!std::isfinite(a.value))
                throw StoreError(step + " has a value that is not finite");
            if (a.input != "key" && a.input != "fine_key" && a.input != "wheel" &&
                a.input != "drag")
                throw StoreError(step + " has input '" + a.input +
                                 "' (expected key, fine_key, wheel or drag)");
            if (k > 0 && a.t_ns < outcome.adjustments[k - 1].t_ns)
                throw StoreError(step + " is earlier than adjustment " +
                                 std::to_string(k) + " (t_ns " + std::to_string(a.t_ns) +
                                 " < " + std::to_string(outcome.adjustments[k - 1].t_ns) +
                                 ")");
        }
        refuse_outcome_columns(where, facts.kind, outcome,
                               {.final_value_and_adjustments = true});
    }
    // The confirmed value is the answer; where it started and how many changes led
    // there are its measures.
    void observe(const StoredTrialMeasures& stored,
                 common::Observation& row) const override {
        row.response = stored.final_value;
        if (stored.start_value) row.measures["start_value"] = *stored.start_value;
        row.measures["adjustments"] = static_cast<double>(stored.adjustments);
    }
};

}  // namespace

const TrialKind& adjust_trial_kind() {
    static const AdjustKind kind;
    return kind;
}

std::vector<PlannedTrial> adjust_block_trials(const Block& block, std::mt19937_64& rng) {
    std::vector<PlannedTrial> trials;
    for (int r = 0; r < block.repeats; ++r)
        for (const std::string& target : block.stimuli) {
            PlannedTrial t;
            t.block = block.id;
            t.task = Task::adjust;
            t.stimulus = target;
            t.shown = {target, block.match};
            t.start_value = adjust_start_value(block, rng);
            trials.push_back(std::move(t));
        }
    return trials;
}

double adjust_start_value(const Block& block, std::mt19937_64& rng) {
    if (block.start == "min") return block.range_min;
    if (block.start == "max") return block.range_max;
    if (block.start != "random") return std::stod(block.start);
    // Uniform over the range on the scale, at one of the points of the browser's series
    // (web_series.h), so the lab and the browser start from the same value.
    const std::vector<double> points = adjust_series_values(block);
    const double u = uniform_unit(rng);
    return points[std::min(points.size() - 1,
                           static_cast<size_t>(u * static_cast<double>(points.size())))];
}

}  // namespace lucent::study
