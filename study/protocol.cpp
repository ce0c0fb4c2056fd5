// Protocol parsing: TOML -> Protocol, with every error naming file, line and key.
#include "study/protocol.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <variant>

#include "common/number_text.h"
#include "renderer/core/knob_toml.h"
#include "renderer/techniques/registry.h"
#include "study/embedded_study_files.h"
#include "study/sha256.h"

namespace lucent::study {
namespace {

// Reads one TOML table, remembering which keys were used so unknown ones are reported.
class TableReader {
public:
    TableReader(const toml::table& table, std::string path, const std::string& source)
        : table_(table), path_(std::move(path)), source_(source) {}

    [[noreturn]] void fail(const toml::node* node, const std::string& key,
                           const std::string& reason) const {
        throw ProtocolError(where(node, key) + ": " + reason);
    }
    // "p.toml:12:17: key 'analysis.primary_model'": where a key was written.
    std::string where(const toml::node* node, const std::string& key) const {
        const toml::source_region& at = node ? node->source() : table_.source();
        std::ostringstream out;
        out << source_ << ":" << at.begin.line << ":" << at.begin.column << ": key '"
            << full(key) << "'";
        return out.str();
    }
    std::string full(const std::string& key) const {
        return path_.empty() ? key : path_ + "." + key;
    }
    const toml::node* get(const std::string& key) {
        used_.insert(key);
        return table_.get(key);
    }
    std::string string(const std::string& key, std::string fallback,
                       bool required = false) {
        const toml::node* node = get(key);
        if (!node) {
            if (required) fail(nullptr, key, "is required");
            return fallback;
        }
        if (!node->is_string()) fail(node, key, "must be a string");
        return std::string(*node->value<std::string>());
    }
    double number(const std::string& key, double fallback, double lo, double hi) {
        const toml::node* node = get(key);
        if (!node) return fallback;
        std::optional<double> value = node->value<double>();
        if (!value || !(node->is_integer() || node->is_floating_point()))
            fail(node, key, "must be a number");
        if (!std::isfinite(*value) || *value < lo || *value > hi) {
            std::ostringstream range;
            range << "must lie in [" << lo << ", " << hi << "], got " << *value;
            fail(node, key, range.str());
        }
        return *value;
    }
    int integer(const std::string& key, int fallback, int lo, int hi) {
        const toml::node* node = get(key);
        if (node && !node->is_integer()) fail(node, key, "must be an integer");
        return static_cast<int>(number(key, fallback, lo, hi));
    }
    bool boolean(const std::string& key, bool fallback) {
        const toml::node* node = get(key);
        if (!node) return fallback;
        if (!node->is_boolean()) fail(node, key, "must be true or false");
        return *node->value<bool>();
    }
    std::vector<std::string> strings(const std::string& key) {
        std::vector<std::string> out;
        const toml::node* node = get(key);
        if (!node) return out;
        const toml::array* array = node->as_array();
        if (!array) fail(node, key, "must be an array of strings");
        for (const toml::node& item : *array) {
            if (!item.is_string()) fail(&item, key, "must be an array of strings");
            out.emplace_back(*item.value<std::string>());
        }
        return out;
    }
    const toml::array* array(const std::string& key) {
        const toml::node* node = get(key);
        if (!node) return nullptr;
        if (!node->is_array()) fail(node, key, "must be an array");
        return node->as_array();
    }
    const toml::table* table(const std::string& key) {
        const toml::node* node = get(key);
        if (!node) return nullptr;
        if (!node->is_table()) fail(node, key, "must be a table");
        return node->as_table();
    }
    // Call after reading: any key not asked for is a typo or an unsupported option.
    void reject_unknown() const {
        for (const auto& [key, node] : table_) {
            if (!used_.count(std::string(key.str())))
                fail(&node, std::string(key.str()), "unknown key");
        }
    }
    const toml::table& raw() const { return table_; }
    const std::string& path() const { return path_; }

private:
    const toml::table& table_;
    std::string path_;
    const std::string& source_;
    std::set<std::string> used_;
};

// A parameter's text as the database and the factor levels hold it: as written, numbers
// in the shortest form that reads back to the same double ("25" for 25.0), arrays as
// "a,b,c". A pre-rendered image's parameters are only this: labels, not knobs.
std::string label_text(const toml::node& node, TableReader& reader,
                       const std::string& key) {
    auto number = [&](const toml::node& item) {
        const double v = *item.value<double>();
        if (!std::isfinite(v)) reader.fail(&item, key, "must be finite");
        return common::shortest_text(v);
    };
    if (node.is_integer() || node.is_floating_point()) return number(node);
    if (node.is_string()) return std::string(*node.value<std::string>());
    if (node.is_boolean()) return *node.value<bool>() ? "true" : "false";
    if (const toml::array* array = node.as_array()) {
        std::string out;
        for (const toml::node& item : *array) {
            if (!(item.is_integer() || item.is_floating_point()))
                reader.fail(&item, key, "array values must be numbers (r,g,b)");
            out += (out.empty() ? "" : ",") + number(item);
        }
        return out;
    }
    reader.fail(&node, key, "must be a number, string, boolean or array of numbers");
}

// A live stimulus's parameter: a knob of its technique, checked by the renderer's one
// TOML knob reader (as stimulus sets read it), and kept in the form it was written (a
// grey "0.6" stays one number, as the database and the factor levels always had it) with
// each number in the shortest text that parse_knob_value() reads back to the same double
// as that reader. See KnobCheck for what a refusal does.
std::string knob_text(const std::vector<Knob>& knobs, const StimulusSpec& stimulus,
                      const toml::node& node, TableReader& reader, const std::string& key,
                      KnobCheck check) {
    const Knob* knob = find_knob(knobs, key);
    const std::string where = "stimulus '" + stimulus.id + "': ";
    try {
        if (!knob) {
            std::string valid;
            for (const Knob& k : knobs) valid += (valid.empty() ? "" : ", ") + k.name;
            throw KnobError("'" + key + "' is not a parameter of technique '" +
                            stimulus.technique + "' (valid: " + valid + ")");
        }
        read_knob_value(*knob, node);
        return label_text(node, reader, key);
    } catch (const KnobError& e) {
        if (check == KnobCheck::lenient) return label_text(node, reader, key);
        reader.fail(&node, key, where + e.what());
    }
}

const toml::table& as_table(const toml::node& node, TableReader& parent,
                            const std::string& key) {
    if (!node.is_table()) parent.fail(&node, key, "entries must be tables");
    return *node.as_table();
}

void read_study(Protocol& p, TableReader& root) {
    const toml::table* study = root.table("study");
    if (!study) root.fail(nullptr, "study", "is required ([study] with name)");
    TableReader r(*study, "study", p.source);
    p.name = r.string("name", "", true);
    p.title = r.string("title", p.name);
    if (const toml::array* bg = r.array("background")) {
        if (bg->size() != 3) r.fail(bg, "background", "must have 3 values (r, g, b)");
        for (int i = 0; i < 3; ++i) {
            std::optional<double> v = (*bg)[i].value<double>();
            if (!v || *v < 0 || *v > 1)
                r.fail(&(*bg)[i], "background", "values must be numbers in [0, 1]");
            p.background[i] = static_cast<float>(*v);
        }
    }
    if (const toml::array* size = r.array("stimulus_size")) {
        std::optional<int64_t> w =
            size->size() == 2 ? (*size)[0].value<int64_t>() : std::nullopt;
        std::optional<int64_t> h =
            size->size() == 2 ? (*size)[1].value<int64_t>() : std::nullopt;
        if (!w || !h || *w < 1 || *h < 1 || *w > 16384 || *h > 16384)
            r.fail(size, "stimulus_size", "must be [width, height] in pixels, 1..16384");
        p.stimulus_width = static_cast<int>(*w);
        p.stimulus_height = static_cast<int>(*h);
    }
    p.break_every = r.integer("break_every", 0, 0, 100000);
    p.inter_trial_ms = r.integer("inter_trial_ms", 500, 0, 60000);
    p.max_failed_catch = r.integer("max_failed_catch", 0, 0, 100000);
    r.reject_unknown();
}

void read_screens(Protocol& p, TableReader& root) {
    const toml::table* screens = root.table("screens");
    if (!screens) return;
    TableReader r(*screens, "screens", p.source);
    p.screens.consent = r.string("consent", "");
    p.screens.instructions = r.string("instructions", "");
    p.screens.practice_done = r.string("practice_done", p.screens.practice_done);
    p.screens.break_text = r.string("break", p.screens.break_text);
    p.screens.debrief = r.string("debrief", "");
    r.reject_unknown();
}

void read_questions(Protocol& p, TableReader& root) {
    // Required (at least one entry) once the blocks say whether anything is rated:
    // check_questions_needed.
    const toml::array* questions = root.array("questions");
    if (!questions) return;
    for (const toml::node& node : *questions) {
        TableReader r(as_table(node, root, "questions"), "questions", p.source);
        Question q;
        q.id = r.string("id", "", true);
        q.text = r.string("text", "", true);
        q.labels = r.strings("labels");
        const toml::node* labels = r.raw().get("labels");
        if (q.labels.empty()) {
            // Default: 7 points with the thesis's end labels.
            q.labels = {"completely disagree", "", "", "", "", "", "completely agree"};
        } else if (q.labels.size() < 2 || q.labels.size() > 7) {
            r.fail(labels, "labels", "needs one label per scale point, 2 to 7 points");
        }
        for (const Question& other : p.questions)
            if (other.id == q.id)
                r.fail(r.raw().get("id"), "id", "duplicate question id '" + q.id + "'");
        r.reject_unknown();
        p.questions.push_back(std::move(q));
    }
}

void read_stimuli(Protocol& p, TableReader& root, const std::string& base_dir,
                  KnobCheck check) {
    const toml::array* stimuli = root.array("stimuli");
    if (!stimuli || stimuli->empty())
        root.fail(stimuli, "stimuli", "at least one [[stimuli]] entry is required");
    for (const toml::node& node : *stimuli) {
        TableReader r(as_table(node, root, "stimuli"), "stimuli", p.source);
        StimulusSpec s;
        s.id = r.string("id", "", true);
        s.technique = r.string("technique", "");
        s.mesh = r.string("mesh", "");
        s.image = r.string("image", "");
        if (s.technique.empty() == s.image.empty())
            r.fail(nullptr, "technique",
                   "stimulus '" + s.id +
                       "' needs exactly one of technique (live) or image (pre-rendered)");
        // The renderer's one list of techniques (its GL-free core).
        if (!s.technique.empty() && !is_technique_name(s.technique))
            r.fail(r.raw().get("technique"), "technique",
                   "unknown technique '" + s.technique +
                       "' (valid: " + technique_names_listed() + ")");
        if (!s.image.empty() && !base_dir.empty() &&
            std::filesystem::path(s.image).is_relative())
            s.image = (std::filesystem::path(base_dir) / s.image).string();
        if (const toml::table* params = r.table("params")) {
            TableReader pr(*params, "stimuli.params", p.source);
            const std::vector<Knob> knobs =
                s.live() ? knobs_for(find_technique(s.technique)) : std::vector<Knob>{};
            for (const auto& [key, value] : *params) {
                const std::string name(key.str());
                s.parameters[name] = s.live()
                                         ? knob_text(knobs, s, value, pr, name, check)
                                         : label_text(value, pr, name);
            }
        }
        s.varies = r.strings("varies");
        // A factor is a parameter, "technique", or "series:NAME": a comparison series
        // whose levels are the stimuli themselves (e.g. one empirical picture against
        // three physically based ones).
        for (const std::string& factor : s.varies)
            if (factor != "technique" && !s.parameters.count(factor) &&
                !(factor.rfind("series:", 0) == 0 && factor.size() > 7))
                r.fail(r.raw().get("varies"), "varies",
                       "'" + factor + "' is not a parameter of stimulus '" + s.id +
                           "' (nor technique or series:NAME)");
        if (p.find_stimulus(s.id))
            r.fail(r.raw().get("id"), "id", "duplicate stimulus id '" + s.id + "'");
        r.reject_unknown();
        p.stimuli.push_back(std::move(s));
    }
}

void check_stimulus_ref(const Protocol& p, TableReader& r, const std::string& key,
                        const std::string& id) {
    if (!p.find_stimulus(id))
        r.fail(r.raw().get(key), key, "no stimulus with id '" + id + "'");
}

// What every block but a rating block has: its own question, answered by one
// response; its stimuli distinct and free of whitespace (trials.shown holds them
// space-separated).
void read_block_question(const Protocol& p, TableReader& r, Block& b) {
    const int n = static_cast<int>(b.stimuli.size());
    for (const std::string& id : b.stimuli)
        if (id.find_first_of(" \t\r\n") != std::string::npos)
            r.fail(r.raw().get("stimuli"), "stimuli",
                   "stimulus id '" + id +
                       "' holds whitespace: a choice trial stores its "
                       "stimuli space-separated");
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < i; ++j)
            if (b.stimuli[i] == b.stimuli[j])
                r.fail(r.raw().get("stimuli"), "stimuli",
                       "stimulus '" + b.stimuli[i] + "' is listed twice in block '" +
                           b.id + "'");
    b.question = r.string("question", "", true);
    b.question_id = r.string("question_id", b.id);
    for (const Question& q : p.questions)
        if (q.id == b.question_id)
            r.fail(r.raw().get("question_id"), "question_id",
                   "'" + b.question_id + "' is already a [[questions]] id");
    for (const Block& other : p.blocks)
        if (other.task != Task::rating && other.question_id == b.question_id)
            r.fail(
                r.raw().get("question_id"), "question_id",
                "'" + b.question_id + "' is already block '" + other.id + "'s question");
}

// How a pair's (or a staircase's) pictures are shown and what its answers are called.
void read_presentation(TableReader& r, Block& b, int pictures) {
    const std::string presentation = r.string("presentation", "side_by_side");
    if (presentation == "sequential")
        b.presentation = Presentation::sequential;
    else if (presentation != "side_by_side")
        r.fail(r.raw().get("presentation"), "presentation",
               "must be \"side_by_side\" or \"sequential\", got '" + presentation + "'");
    b.labels = r.strings("labels");
    // A sequence's pictures have no left and right: they come first, second (third).
    const bool sequence = b.presentation == Presentation::sequential;
    if (b.labels.empty()) {
        if (b.task == Task::triad || b.task == Task::quadruple)
            b.labels = {"first pair", "second pair"};
        else if (pictures == 3)
            b.labels = sequence ? std::vector<std::string>{"first", "second", "third"}
                                : std::vector<std::string>{"left", "middle", "right"};
        else
            b.labels = sequence ? std::vector<std::string>{"first", "second"}
                                : std::vector<std::string>{"left", "right"};
    }
    const size_t answers = b.task == Task::staircase ? static_cast<size_t>(pictures) : 2;
    if (b.labels.size() != answers)
        r.fail(r.raw().get("labels"), "labels",
               answers == 2 ? "needs exactly two answers"
                            : "needs exactly " + std::to_string(answers) + " answers");
    b.duration_ms = r.integer("duration_ms", 1000, 50, 60000);
    b.blank_ms = r.integer("blank_ms", 500, 0, 60000);
}

// The scalar knob `b.knob` of a live stimulus's technique; fails at `key` otherwise.
Knob block_knob(const Protocol& p, TableReader& r, const Block& b,
                const std::string& stimulus, const std::string& key) {
    const StimulusSpec* s = p.find_stimulus(stimulus);
    if (!s || !s->live())
        r.fail(r.raw().get(key), key,
               "'" + stimulus + "' must be a live stimulus (a technique): its knob '" +
                   b.knob + "' is rendered at the participant's value");
    const std::vector<Knob> knobs = knobs_for(find_technique(s->technique));
    const Knob* knob = find_knob(knobs, b.knob);
    if (!knob)
        r.fail(r.raw().get("knob"), "knob",
               "'" + b.knob + "' is not a knob of technique '" + s->technique + "'");
    if (knob->kind != KnobKind::scalar)
        r.fail(r.raw().get("knob"), "knob",
               "'" + b.knob + "' is not a number (only a scalar knob can be turned)");
    return *knob;
}

// A live stimulus's value of a scalar knob: its parameter, else the knob's default.
double knob_value_of(const Protocol& p, const std::string& stimulus, const Knob& knob) {
    if (const std::optional<double> v = p.numeric_parameter(stimulus, knob.name))
        return *v;
    return std::get<double>(knob.default_value);
}

// The keys of an adjust block (design notes: Block in protocol.h).
void read_adjust_block(const Protocol& p, TableReader& r, Block& b) {
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
    read_presentation(r, b, b.pictures());
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

void read_choice_block(const Protocol& p, TableReader& r, Block& b);

// The keys of a block by its task (design notes: Block in protocol.h).
void read_block_task(const Protocol& p, TableReader& r, Block& b) {
    const std::string task = r.string("task", "rating");
    const std::optional<Task> parsed = parse_task(task);
    if (!parsed)
        r.fail(r.raw().get("task"), "task",
               "must be " + task_names_text() + ", got '" + task + "'");
    b.task = *parsed;
    switch (b.task) {
        case Task::rating:
            return;
        case Task::adjust:
            read_block_question(p, r, b);
            return read_adjust_block(p, r, b);
        case Task::staircase:
            read_block_question(p, r, b);
            return read_staircase_block(p, r, b);
        case Task::pair:
        case Task::triad:
        case Task::quadruple:
            read_block_question(p, r, b);
            return read_choice_block(p, r, b);
    }
}

// The keys of a pair, triad or quadruple block (design notes: Block in protocol.h).
void read_choice_block(const Protocol& p, TableReader& r, Block& b) {
    const std::string task = task_name(b.task);
    const int n = static_cast<int>(b.stimuli.size());
    const int shown = pictures_per_trial(b.task);
    if (n < shown)
        r.fail(r.raw().get("stimuli"), "stimuli",
               "a " + task + " block needs at least " + std::to_string(shown) +
                   " stimuli, got " + std::to_string(n));
    b.design = r.string("design", "all");
    if (b.design != "all" && !(b.task == Task::pair && b.design == "cyclic"))
        r.fail(r.raw().get("design"), "design",
               b.task == Task::pair
                   ? "must be \"all\" or \"cyclic\", got '" + b.design + "'"
                   : "must be \"all\" for a " + task + " block, got '" + b.design + "'");
    b.neighbours = r.integer("neighbours", 0, 0, 100000);
    if (b.design == "cyclic") {
        // (i, i+d) and (i, i+n-d) are the same pairs: d up to n/2 gives every pair once.
        if (b.neighbours < 1 || b.neighbours > n / 2)
            r.fail(r.raw().get("neighbours"), "neighbours",
                   "a cyclic design needs 1 <= neighbours <= " + std::to_string(n / 2) +
                       " for " + std::to_string(n) + " stimuli");
    } else if (r.raw().get("neighbours")) {
        r.fail(r.raw().get("neighbours"), "neighbours", "only a cyclic design has them");
    }
    read_presentation(r, b, shown);
    b.identical_catch = r.integer("identical_catch", 0, 0, 1000);
    if (b.identical_catch > 0 && b.task != Task::pair)
        r.fail(r.raw().get("identical_catch"), "identical_catch",
               "only pair blocks have identical-pair catch trials");
    b.obvious_catch = r.strings("obvious_catch");
    if (!b.obvious_catch.empty()) {
        if (b.obvious_catch.size() != 2 || b.obvious_catch[0] == b.obvious_catch[1])
            r.fail(r.raw().get("obvious_catch"), "obvious_catch",
                   "must name two different stimuli: [low, high]");
        for (const std::string& id : b.obvious_catch)
            check_stimulus_ref(p, r, "obvious_catch", id);
    }
    b.obvious_catch_repeats =
        r.integer("obvious_catch_repeats", b.obvious_catch.empty() ? 0 : 1, 0, 1000);
    if (b.obvious_catch.empty() && b.obvious_catch_repeats > 0)
        r.fail(r.raw().get("obvious_catch_repeats"), "obvious_catch_repeats",
               "needs obvious_catch");
    b.series = r.string("series", "");
    if (!b.series.empty()) {
        std::optional<double> previous;
        for (const std::string& id : b.stimuli) {
            const std::optional<double> v = p.numeric_parameter(id, b.series);
            if (!v)
                r.fail(
                    r.raw().get("series"), "series",
                    "stimulus '" + id + "' has no numeric parameter '" + b.series + "'");
            if (b.task != Task::pair && previous && !(*v > *previous))
                r.fail(r.raw().get("stimuli"), "stimuli",
                       "an MLDS series must be listed in increasing '" + b.series +
                           "': '" + id + "' does not follow its predecessor");
            previous = v;
        }
    }
    b.practice = r.integer("practice", 0, 0, 100);
}

void read_trials(Protocol& p, TableReader& root) {
    if (const toml::table* practice = root.table("practice")) {
        TableReader r(*practice, "practice", p.source);
        p.practice = r.strings("stimuli");
        for (const std::string& id : p.practice) check_stimulus_ref(p, r, "stimuli", id);
        r.reject_unknown();
    }
    const toml::array* blocks = root.array("blocks");
    if (!blocks || blocks->empty())
        root.fail(blocks, "blocks", "at least one [[blocks]] entry is required");
    for (const toml::node& node : *blocks) {
        TableReader r(as_table(node, root, "blocks"), "blocks", p.source);
        Block b;
        b.id = r.string("id", "", true);
        b.stimuli = r.strings("stimuli");
        if (b.stimuli.empty())
            r.fail(nullptr, "stimuli", "block '" + b.id + "' has no stimuli");
        for (const std::string& id : b.stimuli) check_stimulus_ref(p, r, "stimuli", id);
        b.repeats = r.integer("repeats", 1, 1, 1000);
        read_block_task(p, r, b);
        for (const Block& other : p.blocks)
            if (other.id == b.id)
                r.fail(r.raw().get("id"), "id", "duplicate block id '" + b.id + "'");
        r.reject_unknown();
        p.blocks.push_back(std::move(b));
    }
    if (const toml::array* catches = root.array("catch_trials")) {
        for (const toml::node& node : *catches) {
            TableReader r(as_table(node, root, "catch_trials"), "catch_trials", p.source);
            CatchTrial c;
            c.id = r.string("id", "", true);
            c.stimulus = r.string("stimulus", "", true);
            check_stimulus_ref(p, r, "stimulus", c.stimulus);
            c.block = r.string("block", p.blocks.front().id);
            const Block* block = p.find_block(c.block);
            if (!block)
                r.fail(r.raw().get("block"), "block",
                       "no block with id '" + c.block + "'");
            if (block->task != Task::rating)
                r.fail(r.raw().get("block"), "block",
                       "block '" + c.block + "' is a " + task_name(block->task) +
                           " block: catch trials are for ratings (a forced choice has "
                           "its own identical_catch and obvious_catch)");
            c.prompt = r.string("prompt", "", true);
            int max_points = 7;
            for (const Question& q : p.questions)
                max_points = std::min(max_points, q.points());
            c.expected = r.integer("expected", 7, 1, max_points);
            c.tolerance = r.integer("tolerance", 0, 0, 6);
            r.reject_unknown();
            p.catch_trials.push_back(std::move(c));
        }
    }
}

void check_questions_needed(const Protocol& p, TableReader& root) {
    if (p.has_rating_trials() && p.questions.empty())
        root.fail(root.raw().get("questions"), "questions",
                  "at least one [[questions]] entry is required (the study rates "
                  "pictures)");
}

void read_randomisation(Protocol& p, TableReader& root) {
    const toml::table* table = root.table("randomisation");
    if (!table) return;
    TableReader r(*table, "randomisation", p.source);
    Randomisation& rz = p.randomisation;
    rz.shuffle = r.boolean("shuffle", true);
    rz.factor = r.string("factor", "stimulus");
    rz.max_repeat = r.integer("max_repeat", 0, 0, 100000);
    rz.min_distance = r.integer("min_distance", 0, 0, 100000);
    rz.counterbalance_blocks = r.boolean("counterbalance_blocks", true);
    if (rz.factor != "stimulus" && rz.factor != "technique") {
        bool known = std::any_of(
            p.stimuli.begin(), p.stimuli.end(),
            [&](const StimulusSpec& s) { return s.parameters.count(rz.factor) > 0; });
        if (!known)
            r.fail(r.raw().get("factor"), "factor",
                   "'" + rz.factor +
                       "' is not 'stimulus', 'technique' or a stimulus parameter");
    }
    r.reject_unknown();
}

void read_analysis_plan(Protocol& p, TableReader& root) {
    const toml::table* table = root.table("analysis");
    if (!table) return;
    TableReader r(*table, "analysis", p.source);
    p.analysis.primary_design = r.string("primary_design", "within");
    if (p.analysis.primary_design != "within" && p.analysis.primary_design != "between")
        r.fail(
            r.raw().get("primary_design"), "primary_design",
            "must be \"within\" or \"between\", got '" + p.analysis.primary_design + "'");
    p.analysis.primary_model = r.string("primary_model", "anova");
    const std::string& model = p.analysis.primary_model;
    if (model.empty() || !std::all_of(model.begin(), model.end(), [](char c) {
            return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
        }))
        r.fail(r.raw().get("primary_model"), "primary_model",
               "must be the name of an analysis (lowercase letters, digits and '_', as "
               "\"anova\", \"clmm\", \"lmm\"), got '" +
                   model + "'");
    if (const toml::node* node = r.raw().get("primary_model"))
        p.analysis.primary_model_at = r.where(node, "primary_model");
    p.analysis.sessions = r.string("sessions", "completed");
    if (p.analysis.sessions != "completed" && p.analysis.sessions != "all")
        r.fail(r.raw().get("sessions"), "sessions",
               "must be \"completed\" or \"all\", got '" + p.analysis.sessions + "'");
    r.reject_unknown();
}

void read_online(Protocol& p, TableReader& root) {
    const toml::table* table = root.table("online");
    if (!table) return;
    TableReader r(*table, "online", p.source);
    p.online.completion_code = r.string("completion_code", "");
    p.online.completion_url = r.string("completion_url", "");
    const std::string& url = p.online.completion_url;
    if (!url.empty() && url.rfind("https://", 0) != 0 && url.rfind("http://", 0) != 0)
        r.fail(r.raw().get("completion_url"), "completion_url",
               "must start with https:// or http://, got '" + url + "'");
    for (const std::string* text : {&p.online.completion_code, &p.online.completion_url})
        for (char c : *text)
            if (static_cast<unsigned char>(c) < 0x20 || c == '"' || c == '<' || c == '>')
                r.fail(r.raw().get(text == &url ? "completion_url" : "completion_code"),
                       text == &url ? "completion_url" : "completion_code",
                       "must not hold control characters, quotes or angle brackets");
    r.reject_unknown();
}

}  // namespace

const char* task_name(Task task) {
    switch (task) {
        case Task::rating:
            return "rating";
        case Task::pair:
            return "pair";
        case Task::triad:
            return "triad";
        case Task::quadruple:
            return "quadruple";
        case Task::adjust:
            return "adjust";
        case Task::staircase:
            return "staircase";
    }
    return "rating";
}

std::optional<Task> parse_task(std::string_view text) {
    for (Task t : kAllTasks)
        if (text == task_name(t)) return t;
    return std::nullopt;
}

std::string task_names_text() {
    std::string text;
    for (std::size_t i = 0; i < kAllTasks.size(); ++i)
        text += std::string(i == 0                      ? ""
                            : i + 1 == kAllTasks.size() ? " or "
                                                        : ", ") +
                "\"" + task_name(kAllTasks[i]) + "\"";
    return text;
}

bool is_choice_task(Task task) {
    switch (task) {
        case Task::pair:
        case Task::triad:
        case Task::quadruple:
        case Task::staircase:
            return true;
        case Task::rating:
        case Task::adjust:
            return false;
    }
    return false;
}

bool is_scaling_task(Task task) {
    switch (task) {
        case Task::pair:
        case Task::triad:
        case Task::quadruple:
            return true;
        case Task::rating:
        case Task::adjust:
        case Task::staircase:
            return false;
    }
    return false;
}

int pictures_per_trial(Task task) {
    switch (task) {
        case Task::rating:
            return 1;
        case Task::pair:
            return 2;
        case Task::triad:
            return 3;
        case Task::quadruple:
            return 4;
        case Task::adjust:
        case Task::staircase:
            return 2;
    }
    return 1;
}

int Block::pictures() const {
    return task == Task::staircase && staircase_trial == "oddity"
               ? 3
               : pictures_per_trial(task);
}

int Block::answers() const {
    switch (task) {
        case Task::rating:
            return 0;
        case Task::adjust:
            return 1;
        case Task::staircase:
            return pictures();
        default:
            return 2;
    }
}

std::optional<double> Protocol::numeric_parameter(std::string_view stimulus,
                                                  const std::string& parameter) const {
    const StimulusSpec* s = find_stimulus(stimulus);
    if (!s) return std::nullopt;
    const auto it = s->parameters.find(parameter);
    if (it == s->parameters.end()) return std::nullopt;
    return common::parse_finite(it->second);
}

const Block* Protocol::find_block(std::string_view id) const {
    for (const Block& b : blocks)
        if (b.id == id) return &b;
    return nullptr;
}

bool Protocol::has_rating_trials() const {
    return !practice.empty() ||
           std::any_of(blocks.begin(), blocks.end(),
                       [](const Block& b) { return b.task == Task::rating; });
}

const StimulusSpec* Protocol::find_stimulus(std::string_view id) const {
    for (const StimulusSpec& s : stimuli)
        if (s.id == id) return &s;
    return nullptr;
}

std::string Protocol::picture_key(const StimulusSpec& stimulus) {
    if (!stimulus.live()) {
        std::ifstream in(stimulus.image, std::ios::binary);
        std::ostringstream bytes;
        if (in && (bytes << in.rdbuf())) return "image sha256:" + sha256_hex(bytes.str());
        return "image path:" +
               std::filesystem::absolute(stimulus.image).lexically_normal().string();
    }
    std::string key = "live " + stimulus.technique + " " + stimulus.mesh;
    for (const auto& [name, value] : stimulus.parameters) key += " " + name + "=" + value;
    return key;
}

std::map<std::string, std::string> Protocol::levels_of(std::string_view factor) const {
    std::map<std::string, std::string> levels;
    if (factor != "stimulus") {
        for (const StimulusSpec& s : stimuli) levels[s.id] = level_of(s, factor);
        return levels;
    }
    std::map<std::string, std::string> first_id_of_picture;
    for (const StimulusSpec& s : stimuli)
        levels[s.id] = first_id_of_picture.emplace(picture_key(s), s.id).first->second;
    return levels;
}

std::string Protocol::level_of(const StimulusSpec& stimulus,
                               std::string_view factor) const {
    if (factor == "stimulus") {
        const auto levels = levels_of(factor);
        const auto it = levels.find(stimulus.id);
        return it == levels.end() ? stimulus.id : it->second;
    }
    if (factor == "technique")
        return stimulus.technique.empty() ? "image" : stimulus.technique;
    if (factor.rfind("series:", 0) == 0) return stimulus.id;
    auto it = stimulus.parameters.find(std::string(factor));
    return it == stimulus.parameters.end() ? std::string() : it->second;
}

Protocol parse_protocol(std::string_view text, const std::string& source,
                        const std::string& base_dir, KnobCheck check) {
    toml::table root_table;
    try {
        root_table = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        std::ostringstream out;
        out << source << ":" << e.source().begin.line << ":" << e.source().begin.column
            << ": " << e.description();
        throw ProtocolError(out.str());
    }
    Protocol p;
    p.source = source;
    p.text = std::string(text);
    TableReader root(root_table, "", p.source);
    read_study(p, root);
    read_screens(p, root);
    read_questions(p, root);
    read_stimuli(p, root, base_dir, check);
    read_trials(p, root);
    check_questions_needed(p, root);
    read_randomisation(p, root);
    read_analysis_plan(p, root);
    read_online(p, root);
    root.reject_unknown();
    return p;
}

Protocol load_protocol_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ProtocolError(path + ": cannot open protocol file");
    std::ostringstream text;
    text << in.rdbuf();
    return parse_protocol(text.str(), path,
                          std::filesystem::absolute(path).parent_path().string());
}

std::vector<std::string> builtin_protocol_names() {
    return {"thesis", "fabrics", "scaling", "matching", "jnd"};
}

Protocol builtin_protocol(std::string_view name) {
    std::optional<std::string_view> text =
        embedded::study_file("presets/" + std::string(name) + ".toml");
    if (!text) {
        std::string valid;
        for (const std::string& n : builtin_protocol_names())
            valid += (valid.empty() ? "" : ", ") + n;
        throw ProtocolError("unknown preset '" + std::string(name) +
                            "' (valid: " + valid + ")");
    }
    return parse_protocol(*text, "preset:" + std::string(name));
}

std::string protocol_hash(std::string_view text) { return sha256_hex(text); }

}  // namespace lucent::study
