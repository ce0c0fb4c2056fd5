#include "study/trials/staircase/staircase_trials.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/number_text.h"
#include "common/observation_table.h"
#include "common/portable_random.h"
#include "study/store_rules.h"
#include "study/trials/block_keys.h"
#include "study/trials/table_reader.h"

namespace lucent::study {

using common::portable_shuffle;

namespace {

// The keys of one [[blocks.staircases]] entry.
Block::Procedure read_procedure(TableReader& r, const Block& b, double max_delta) {
    Block::Procedure s;
    s.id = r.string("id", "", true);
    if (s.id.find_first_of(" \t\r\n/") != std::string::npos)
        r.fail(r.raw().get("id"), "id", "must not hold whitespace or '/'");
    s.method = r.string("method", "updown");
    if (s.method != "updown" && s.method != "quest")
        r.fail(r.raw().get("method"), "method",
               "must be \"updown\" or \"quest\", got '" + s.method + "'");
    s.min_delta = r.number("min_delta", 0, 0, max_delta);
    s.max_delta = r.number("max_delta", max_delta, 0, max_delta);
    if (!(s.max_delta > s.min_delta))
        r.fail(r.raw().get("max_delta"), "max_delta",
               "must be above min_delta (" + common::shortest_text(s.min_delta) + ")");
    s.start = r.number("start", 0, s.min_delta, s.max_delta);
    if (!r.raw().get("start")) r.fail(nullptr, "start", "is required");
    s.max_trials = r.integer("max_trials", 50, 1, 1000);
    if (s.method == "updown") {
        s.n_up = r.integer("n_up", 1, 1, 10);
        s.n_down = r.integer("n_down", 3, 1, 10);
        s.step_type = r.string("step_type", "lin");
        if (s.step_type != "lin" && s.step_type != "log" && s.step_type != "db")
            r.fail(r.raw().get("step_type"), "step_type",
                   "must be \"lin\", \"log\" or \"db\", got '" + s.step_type + "'");
        if (s.step_type != "lin" && !(s.start > 0))
            r.fail(r.raw().get("start"), "start",
                   "must be above 0 with " + s.step_type + " steps");
        if (const toml::array* steps = r.array("step_sizes")) {
            for (const toml::node& n : *steps) {
                const std::optional<double> v = n.value<double>();
                if (!v || !(n.is_integer() || n.is_floating_point()) ||
                    !std::isfinite(*v) || !(*v > 0))
                    r.fail(&n, "step_sizes", "must be numbers above 0");
                s.step_sizes.push_back(*v);
            }
        }
        if (s.step_sizes.empty())
            r.fail(r.raw().get("step_sizes"), "step_sizes",
                   "is required: the step after 0, 1, 2... reversals");
        s.n_trials = r.integer("n_trials", 0, 0, 1000);
        s.n_reversals = r.integer("n_reversals", 0, 0, 1000);
        // PsychoPy runs to n_trials AND n_reversals (at least the step sizes' count).
        const int reversals =
            std::max<int>(s.n_reversals, static_cast<int>(s.step_sizes.size()));
        if (s.max_trials < std::max(s.n_trials, reversals))
            r.fail(r.raw().get("max_trials"), "max_trials",
                   "must be at least n_trials and n_reversals (" +
                       std::to_string(std::max(s.n_trials, reversals)) +
                       "): the plan holds max_trials slots");
    } else {
        s.start_sd = r.number("start_sd", 0, 0, 1e300);
        if (!(s.start_sd > 0))
            r.fail(r.raw().get("start_sd"), "start_sd", "is required and above 0");
        const double guess = b.staircase_trial == "oddity" ? 1.0 / 3 : 0.5;
        s.p_threshold = r.number("p_threshold", guess == 0.5 ? 0.82 : 0.75, 0, 1);
        if (!(s.p_threshold > guess) || !(s.p_threshold < 1))
            r.fail(r.raw().get("p_threshold"), "p_threshold",
                   "must lie between the guess rate (" + common::shortest_text(guess) +
                       ") and 1");
        s.beta = r.number("beta", 3.5, 1e-6, 1e6);
        s.delta = r.number("delta", 0.01, 0, 0.5);
        // Default grid: 500 grains over twice the deltas' range, so it covers every
        // delta the block allows wherever the prior is centred.
        s.quest_range = r.number("range", 0, 0, 1e300);
        const double grid =
            s.quest_range > 0 ? s.quest_range : 2 * (s.max_delta - s.min_delta);
        s.grain = r.number("grain", grid / 500, 1e-12, grid);
        if (!(s.grain > 0)) r.fail(r.raw().get("grain"), "grain", "must be above 0");
        s.n_trials = r.integer("n_trials", s.max_trials, 1, 1000);
        if (s.max_trials < s.n_trials)
            r.fail(r.raw().get("max_trials"), "max_trials",
                   "must be at least n_trials (" + std::to_string(s.n_trials) + ")");
    }
    r.reject_unknown();
    return s;
}

// The keys of a staircase block (design notes: Block in protocol.h).
void read_staircase_block(const Protocol& p, TableReader& r, Block& b) {
    read_block_question(p, r, b);
    b.knob = r.string("knob", "", true);
    b.direction = r.string("direction", "up");
    if (b.direction != "up" && b.direction != "down")
        r.fail(r.raw().get("direction"), "direction",
               "must be \"up\" or \"down\", got '" + b.direction + "'");
    // The room each standard leaves in the knob's range bounds the delta.
    double room = std::numeric_limits<double>::infinity();
    for (const std::string& standard : b.stimuli) {
        const Knob knob = block_knob(p, r, b, standard, "stimuli");
        const double value = knob_value_of(p, standard, knob);
        room = std::min(room, b.direction == "up" ? knob.max - value : value - knob.min);
    }
    if (!(room > 0))
        r.fail(r.raw().get("stimuli"), "stimuli",
               "a standard's '" + b.knob + "' is at the end of the knob's range: no " +
                   b.direction + "ward delta is possible");
    b.staircase_trial = r.string("trial", "pair");
    if (b.staircase_trial != "pair" && b.staircase_trial != "oddity")
        r.fail(r.raw().get("trial"), "trial",
               "must be \"pair\" or \"oddity\", got '" + b.staircase_trial + "'");
    read_presentation(r, b, b.pictures(), false);
    // The flow's sequence has two parts (a pair's pictures), not three.
    if (b.staircase_trial == "oddity" && b.presentation == Presentation::sequential)
        r.fail(r.raw().get("presentation"), "presentation",
               "an odd-one-out staircase is shown side by side (\"sequential\" shows two "
               "pictures, not three)");
    const toml::array* procedures = r.array("staircases");
    if (!procedures || procedures->empty())
        r.fail(procedures, "staircases",
               "at least one [[blocks.staircases]] entry is required");
    for (const toml::node& node : *procedures) {
        if (!node.is_table()) r.fail(&node, "staircases", "must be tables");
        TableReader pr(*node.as_table(), r.full("staircases"), p.source);
        Block::Procedure s = read_procedure(pr, b, room);
        for (const Block::Procedure& other : b.procedures)
            if (other.id == s.id)
                pr.fail(pr.raw().get("id"), "id",
                        "duplicate staircase id '" + s.id + "'");
        b.procedures.push_back(std::move(s));
    }
    double low = b.procedures.front().min_delta, high = b.procedures.front().max_delta;
    double smallest_linear_step = std::numeric_limits<double>::infinity();
    for (const Block::Procedure& s : b.procedures) {
        low = std::min(low, s.min_delta);
        high = std::max(high, s.max_delta);
        if (s.method == "updown" && s.step_type == "lin")
            for (double step : s.step_sizes)
                smallest_linear_step = std::min(smallest_linear_step, step);
    }
    const double span = high - low;
    b.ladder_step = r.number(
        "ladder_step",
        std::isfinite(smallest_linear_step) ? smallest_linear_step : span / 32, 0, span);
    if (!(b.ladder_step > 0))
        r.fail(r.raw().get("ladder_step"), "ladder_step", "must be above 0");
}

class StaircaseKind : public TrialKind {
public:
    const char* name() const override { return "staircase"; }
    bool is_choice() const override { return true; }
    bool is_scaling() const override { return false; }
    int pictures_per_trial() const override { return 2; }
    // An odd-one-out staircase shows the comparison among two standards.
    int pictures(const Block& b) const override {
        return b.staircase_trial == "oddity" ? 3 : 2;
    }
    int answers(const Block& b) const override { return pictures(b); }
    TrialScreen screen() const override { return TrialScreen::staircase; }
    const char* analysed_as() const override { return "thresholds"; }
    void read_block(const Protocol& p, TableReader& keys, Block& b) const override {
        read_staircase_block(p, keys, b);
    }
    std::vector<PlannedTrial> plan_block(const Protocol&, const Block& block,
                                         std::mt19937_64& rng) const override {
        return staircase_block_trials(block, rng);
    }
    // A finite intensity (the delta shown); finishing a procedure only for a slot of
    // one.
    void check_outcome(const std::string& where, const TrialAnswerFacts& facts,
                       const TrialOutcome& outcome) const override {
        refuse_outcome_columns(where, facts.kind, outcome, {.intensity = true});
        if (!outcome.intensity)
            throw StoreError(where + " is a staircase trial without an intensity");
        if (!std::isfinite(*outcome.intensity))
            throw StoreError(where + " has an intensity that is not finite");
        if (outcome.finishes_staircase && facts.staircase.empty())
            throw StoreError(where + " finishes a staircase but was planned without one");
    }
    void observe(const StoredTrialMeasures& stored,
                 common::Observation& row) const override {
        row.procedure = stored.staircase;
        if (stored.intensity) row.measures["intensity"] = *stored.intensity;
    }
    // Its rounds are its procedures' order; the shuffle leaves them.
    bool shuffled() const override { return false; }
    // A slot's own level (unique: constraints never move it).
    std::string sequence_level(const PlannedTrial& trial,
                               const std::map<std::string, std::string>&) const override {
        return "staircase " + trial.block + " " + std::to_string(trial.position);
    }
};

}  // namespace

const TrialKind& staircase_trial_kind() {
    static const StaircaseKind kind;
    return kind;
}

std::vector<PlannedTrial> staircase_block_trials(const Block& block,
                                                 std::mt19937_64& rng) {
    struct Slots {
        std::string standard, label;
        std::vector<int> places;  // the comparison's place per slot, in order
    };
    const int k = block.pictures();
    std::vector<Slots> procedures;
    for (const std::string& standard : block.stimuli)
        for (const Block::Procedure& p : block.procedures) {
            Slots s{standard, standard + "/" + p.id, {}};
            // Every place equally often; the remainder's places distinct, at random.
            for (int i = 0; i < p.max_trials - p.max_trials % k; ++i)
                s.places.push_back(1 + i % k);
            std::vector<int> rest(k);
            for (int i = 0; i < k; ++i) rest[i] = i + 1;
            portable_shuffle(rest, rng);
            for (int i = 0; i < p.max_trials % k; ++i) s.places.push_back(rest[i]);
            portable_shuffle(s.places, rng);
            procedures.push_back(std::move(s));
        }
    std::vector<PlannedTrial> trials;
    std::vector<size_t> used(procedures.size(), 0);
    for (;;) {
        std::vector<size_t> round;
        for (size_t i = 0; i < procedures.size(); ++i)
            if (used[i] < procedures[i].places.size()) round.push_back(i);
        if (round.empty()) break;
        portable_shuffle(round, rng);
        for (size_t i : round) {
            PlannedTrial t;
            t.block = block.id;
            t.task = Task::staircase;
            t.stimulus = procedures[i].standard;
            t.shown.assign(k, procedures[i].standard);
            t.staircase = procedures[i].label;
            t.expected = procedures[i].places[used[i]++];
            trials.push_back(std::move(t));
        }
    }
    return trials;
}

}  // namespace lucent::study
