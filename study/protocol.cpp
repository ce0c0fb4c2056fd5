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
#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"
#include "study/embedded_study_files.h"
#include "study/sha256.h"
#include "study/trials/block_keys.h"
#include "study/trials/table_reader.h"
#include "study/trials/trial_kind.h"

namespace lucent::study {
namespace {

// A parameter's text as the database and the factor levels hold it (the renderer's one
// parameter_text). A pre-rendered image's parameters are only this: labels, not knobs.
std::string label_text(const toml::node& node, TableReader& reader,
                       const std::string& key) {
    try {
        return parameter_text(node);
    } catch (const ParameterTextError& e) {
        reader.fail(e.node, key, e.what());
    }
}

// A live stimulus's parameter: a knob of its technique, checked by the renderer's one
// TOML knob reader (as stimulus sets read it), and kept in the form it was written (a
// grey "0.6" stays one number, as the database and the factor levels always had it) with
// each number in the shortest text that parse_knob_value() reads back to the same double
// as that reader. See KnobCheck for what a refusal does.
std::string knob_text(const std::vector<Knob>& knobs, const Stimulus& stimulus,
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
    p.stimulus_set = r.string("stimulus_set", "");
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

// The stimulus set a protocol names ([study] stimulus_set), as stored with it
// ([embedded_stimulus_set]) or else read from the preset or file; the protocol's text
// gains the embedded copy. The set's own errors keep their file:line.
std::vector<Stimulus> read_named_set(Protocol& p, TableReader& root,
                                     const std::string& base_dir) {
    const toml::node* named_at = root.raw().at_path("study.stimulus_set").node();
    std::string text, source = p.stimulus_set;
    std::string directory = ".";
    if (const toml::table* stored = root.table("embedded_stimulus_set")) {
        TableReader r(*stored, "embedded_stimulus_set", p.source);
        const std::string named = r.string("source", "", true);
        if (named != p.stimulus_set)
            r.fail(stored->get("source"), "source",
                   "is '" + named + "', not the [study] stimulus_set '" + p.stimulus_set +
                       "'");
        text = r.string("text", "", true);
        directory = r.string("directory", ".");
        r.reject_unknown();
    } else if (p.stimulus_set.rfind("preset:", 0) == 0) {
        const std::string name = p.stimulus_set.substr(7);
        const std::optional<std::string_view> preset = set_preset_text(name);
        if (!preset) {
            std::string valid;
            for (const std::string& known : set_preset_names())
                valid += (valid.empty() ? "" : ", ") + known;
            root.fail(named_at, "study.stimulus_set",
                      "unknown preset '" + name + "' (valid: " + valid + ")");
        }
        text = std::string(*preset);
    } else {
        std::filesystem::path file(p.stimulus_set);
        if (file.is_relative() && !base_dir.empty()) file = base_dir / file;
        std::ifstream in(file, std::ios::binary);
        std::ostringstream bytes;
        if (!in || !(bytes << in.rdbuf()))
            root.fail(named_at, "study.stimulus_set",
                      "cannot read the stimulus set '" + file.string() + "'");
        text = bytes.str();
        source = file.string();
        directory = std::filesystem::absolute(file).parent_path().string();
    }
    std::vector<Stimulus> stimuli;
    try {
        stimuli =
            parse_stimulus_set(text, source, directory, default_set_catalog()).stimuli;
    } catch (const StimulusSetError& e) {
        throw ProtocolError(p.source + ": study.stimulus_set: " + e.what());
    }
    if (!root.raw().get("embedded_stimulus_set")) {
        const toml::table embedded{
            {"source", p.stimulus_set}, {"text", text}, {"directory", directory}};
        std::ostringstream out;
        out << "\n# The stimulus set as it was read (lucent adds it), so that the stored "
               "protocol\n# needs no other file.\n[embedded_stimulus_set]\n"
            << embedded << "\n";
        p.text += out.str();
    }
    return stimuli;
}

void read_stimuli(Protocol& p, TableReader& root, const std::string& base_dir,
                  KnobCheck check) {
    if (!p.stimulus_set.empty()) p.stimuli = read_named_set(p, root, base_dir);
    const toml::array* stimuli = root.array("stimuli");
    if (!stimuli || stimuli->empty()) {
        if (!p.stimuli.empty()) return;
        root.fail(stimuli, "stimuli",
                  "at least one [[stimuli]] entry is required (or [study] stimulus_set)");
    }
    for (const toml::node& node : *stimuli) {
        TableReader r(as_table(node, root, "stimuli"), "stimuli", p.source);
        Stimulus s;
        s.id = r.string("id", "", true);
        s.technique = r.string("technique", "");
        s.mesh = r.string("mesh", "");
        s.mesh_name = s.mesh;
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
        const std::vector<Knob> knobs =
            s.live() ? knobs_for(find_technique(s.technique)) : std::vector<Knob>{};
        if (const toml::table* params = r.table("params")) {
            TableReader pr(*params, "stimuli.params", p.source);
            for (const auto& [key, value] : *params) {
                const std::string name(key.str());
                s.parameters[name] = s.live()
                                         ? knob_text(knobs, s, value, pr, name, check)
                                         : label_text(value, pr, name);
            }
        }
        // The experimenter's own factors: named levels no renderer reads.
        if (const toml::table* factors = r.table("factors")) {
            TableReader fr(*factors, "stimuli.factors", p.source);
            for (const auto& [key, value] : *factors) {
                const std::string name(key.str());
                if (s.parameters.count(name) || find_knob(knobs, name))
                    fr.fail(&value, name,
                            "'" + name + "' is a parameter of stimulus '" + s.id +
                                "': set it in params, not as a factor");
                if (name == "technique" || name.find(':') != std::string::npos)
                    fr.fail(&value, name, "'" + name + "' is not a factor name");
                s.factors[name] = label_text(value, fr, name);
            }
        }
        s.varies = r.strings("varies");
        // A factor is a parameter, an own factor, "technique", or "series:NAME": a
        // comparison series whose levels are the stimuli themselves (e.g. one empirical
        // picture against three physically based ones).
        for (const std::string& factor : s.varies)
            if (factor != "technique" && !s.parameters.count(factor) &&
                !s.factors.count(factor) &&
                !(factor.rfind("series:", 0) == 0 && factor.size() > 7))
                r.fail(r.raw().get("varies"), "varies",
                       "'" + factor + "' is not a parameter or factor of stimulus '" +
                           s.id + "' (nor technique or series:NAME)");
        if (p.find_stimulus(s.id))
            r.fail(r.raw().get("id"), "id", "duplicate stimulus id '" + s.id + "'");
        r.reject_unknown();
        p.stimuli.push_back(std::move(s));
    }
}

// The keys of a block by its task: the kind reads its own (trials/<kind>/).
void read_block_task(const Protocol& p, TableReader& r, Block& b) {
    const std::string task = r.string("task", "rating");
    const std::optional<Task> parsed = parse_task(task);
    if (!parsed)
        r.fail(r.raw().get("task"), "task",
               "must be " + task_names_text() + ", got '" + task + "'");
    b.task = *parsed;
    b.task->read_block(p, r, b);
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
            [&](const Stimulus& s) { return s.columns().count(rz.factor) > 0; });
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

const char* task_name(Task task) { return task->name(); }

std::optional<Task> parse_task(std::string_view text) {
    for (Task t : all_tasks())
        if (text == task_name(t)) return t;
    return std::nullopt;
}

std::string task_names_text() {
    const std::vector<Task> tasks = all_tasks();
    std::string text;
    for (std::size_t i = 0; i < tasks.size(); ++i)
        text += std::string(i == 0                  ? ""
                            : i + 1 == tasks.size() ? " or "
                                                    : ", ") +
                "\"" + task_name(tasks[i]) + "\"";
    return text;
}

bool is_choice_task(Task task) { return task->is_choice(); }

bool is_scaling_task(Task task) { return task->is_scaling(); }

int pictures_per_trial(Task task) { return task->pictures_per_trial(); }

int Block::pictures() const { return task->pictures(*this); }

int Block::answers() const { return task->answers(*this); }

std::optional<double> Protocol::numeric_parameter(std::string_view stimulus,
                                                  const std::string& parameter) const {
    const Stimulus* s = find_stimulus(stimulus);
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

const Stimulus* Protocol::find_stimulus(std::string_view id) const {
    for (const Stimulus& s : stimuli)
        if (s.id == id) return &s;
    return nullptr;
}

std::string Protocol::picture_key(const Stimulus& stimulus) {
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
        for (const Stimulus& s : stimuli) levels[s.id] = level_of(s, factor);
        return levels;
    }
    std::map<std::string, std::string> first_id_of_picture;
    for (const Stimulus& s : stimuli)
        levels[s.id] = first_id_of_picture.emplace(picture_key(s), s.id).first->second;
    return levels;
}

std::string Protocol::level_of(const Stimulus& stimulus, std::string_view factor) const {
    if (factor == "stimulus") {
        const auto levels = levels_of(factor);
        const auto it = levels.find(stimulus.id);
        return it == levels.end() ? stimulus.id : it->second;
    }
    if (factor == "technique")
        return stimulus.technique.empty() ? "image" : stimulus.technique;
    if (factor.rfind("series:", 0) == 0) return stimulus.id;
    const std::map<std::string, std::string> columns = stimulus.columns();
    auto it = columns.find(std::string(factor));
    return it == columns.end() ? std::string() : it->second;
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
