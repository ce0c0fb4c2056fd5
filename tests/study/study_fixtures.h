#pragma once
// A small protocol and helpers that fill a study database the way the runner does.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "study/protocol.h"
#include "study/sqlite/sqlite_store.h"
#include "study/store_types.h"
#include "study/trial_plan.h"

namespace lucent::test {

// The one-line error parse_protocol gives `text` read as `source`; "" when it reads.
inline std::string protocol_error_of(const std::string& text,
                                     const std::string& source = "bad.toml",
                                     study::KnobCheck check = study::KnobCheck::strict) {
    try {
        study::parse_protocol(text, source, "", check);
    } catch (const study::ProtocolError& e) {
        return e.what();
    }
    return "";
}

// A hand-written provenance for every stimulus of protocol `p`: `albedo` is the one
// value the tests vary.
inline std::vector<study::StimulusProvenance> provenance_for(const study::Protocol& p,
                                                             const std::string& albedo) {
    std::vector<study::StimulusProvenance> out;
    for (const Stimulus& s : p.stimuli) {
        study::StimulusProvenance v;
        v.stimulus = s.id;
        v.source = "live";
        v.technique = s.technique;
        v.mesh = s.mesh;
        v.mesh_hash = "00000000000000aa";
        v.values = {{"albedo", albedo}, {"fov_y", "60"}};
        for (const auto& [name, value] : s.parameters) v.values.emplace_back(name, value);
        v.software_version = "9.9.9";
        v.build_hash = "test";
        out.push_back(v);
    }
    return out;
}

// A station's environment: its machine id, GPU and display refresh rate.
inline study::SessionEnvironment environment(const std::string& machine,
                                             const std::string& gpu, double hz) {
    study::SessionEnvironment env;
    env.machine_id = machine;
    env.software_version = "9.9.9";
    env.build_hash = "test";
    env.gl_vendor = "vendor " + machine;
    env.gl_renderer = gpu;
    env.display_mode = "1280x1024 fullscreen";
    env.display_refresh_hz = hz;
    return env;
}

// Turns a database written by this build into one of schema `version`, as an older build
// left it: every table and index rebuilt from migrations 1..version with the columns
// those had, later tables dropped. Rows of the kept columns stay.
inline void downgrade_schema(study::Database& db, int version) {
    study::Database model(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    study::migrate(model, version);
    std::vector<std::pair<std::string, std::string>> tables, indexes;  // name, sql
    {
        study::Statement s = model.prepare(
            "SELECT type, name, sql FROM sqlite_schema WHERE sql IS NOT NULL ORDER BY "
            "rowid");
        while (s.step())
            (s.text(0) == "table" ? tables : indexes).emplace_back(s.text(1), s.text(2));
    }
    db.exec("PRAGMA foreign_keys = OFF");
    std::vector<std::string> later;
    {
        study::Statement s =
            db.prepare("SELECT name FROM sqlite_schema WHERE type = 'table'");
        while (s.step()) later.push_back(s.text(0));
    }
    for (const std::string& name : later) {
        const bool kept = std::any_of(tables.begin(), tables.end(),
                                      [&](const auto& t) { return t.first == name; });
        if (!kept) db.exec("DROP TABLE " + name);
    }
    for (const auto& [name, sql] : tables) {
        std::string columns;
        study::Statement info = model.prepare("SELECT name FROM pragma_table_info(?)");
        info.bind(1, name);
        while (info.step()) columns += (columns.empty() ? "" : ", ") + info.text(0);
        std::string rebuilt = sql;
        rebuilt.replace(rebuilt.find(name), name.size(), name + "_old_schema");
        db.exec(rebuilt);
        db.exec("INSERT INTO " + name + "_old_schema (" + columns + ") SELECT " +
                columns + " FROM " + name);
        db.exec("DROP TABLE " + name);
        db.exec("ALTER TABLE " + name + "_old_schema RENAME TO " + name);
    }
    for (const auto& [name, sql] : indexes) db.exec(sql);
    db.exec("PRAGMA user_version = " + std::to_string(version));
    db.exec("PRAGMA foreign_keys = ON");
}

// 3 rated stimuli varying thickness_exponent, 1 practice, 1 catch (expected 7), 2
// questions.
inline const char* kSmallProtocol = R"toml(
[study]
name = "small"
break_every = 2

[[questions]]
id = "translucent"
text = "The object looks translucent."

[[questions]]
id = "realistic"
text = "The object looks realistic."

[[stimuli]]
id = "a"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 18, backlight = 1.2 }
varies = ["thickness_exponent"]

[[stimuli]]
id = "b"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 25, backlight = 1.2 }
varies = ["thickness_exponent"]

[[stimuli]]
id = "c"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 30, backlight = 1.2 }
varies = ["thickness_exponent"]

[[stimuli]]
id = "p"
technique = "ward"
mesh = "sphere"
params = { roughness = 0.2 }

[practice]
stimuli = ["p"]

[[blocks]]
id = "main"
stimuli = ["a", "b", "c"]

[[catch_trials]]
id = "attention"
stimulus = "a"
block = "main"
prompt = "Choose 7"
expected = 7
)toml";

// Forced choices beside ratings: 5 stimuli of a thickness series, a rating block, a
// pair block (all pairs, repeated twice, 2 identical and 1 obvious catch trials, 1
// practice trial) and a triad block (MLDS) in sequence.
inline const char* kChoiceProtocol = R"toml(
[study]
name = "choices"

[[questions]]
id = "translucent"
text = "The object looks translucent."

[[stimuli]]
id = "s1"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 10 }

[[stimuli]]
id = "s2"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 15 }

[[stimuli]]
id = "s3"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 20 }

[[stimuli]]
id = "s4"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 25 }

[[stimuli]]
id = "s5"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 30 }

[[blocks]]
id = "ratings"
stimuli = ["s1", "s3", "s5"]

[[blocks]]
id = "pairs"
task = "pair"
stimuli = ["s1", "s2", "s3", "s4", "s5"]
question = "Which looks more translucent?"
question_id = "more_translucent"
repeats = 2
identical_catch = 2
obvious_catch = ["s5", "s1"]
series = "thickness_exponent"
practice = 1

[[blocks]]
id = "mlds"
task = "triad"
stimuli = ["s1", "s2", "s3", "s4", "s5"]
question = "Which pair differs more?"
series = "thickness_exponent"
presentation = "sequential"
duration_ms = 800
blank_ms = 300
obvious_catch = ["s1", "s5"]
)toml";

// Matching and thresholds (issue 31) beside ratings: a rating block, an adjust block
// (two targets, one live match object) and a pair staircase block over one standard
// with two interleaved up/down procedures, "target/a" and "target/b", 4 slots each.
inline const char* kMatchingProtocol = R"toml(
[study]
name = "matching"

[[questions]]
id = "translucent"
text = "The object looks translucent."

[[stimuli]]
id = "rated"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 2.0 }

[[stimuli]]
id = "target"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 1.5 }

[[stimuli]]
id = "target2"
technique = "empirical"
mesh = "sphere"
params = { thickness_exponent = 3.0 }

[[stimuli]]
id = "match"
technique = "empirical"
mesh = "sphere"

[[blocks]]
id = "ratings"
stimuli = ["rated"]

[[blocks]]
id = "m"
task = "adjust"
stimuli = ["target", "target2"]
match = "match"
knob = "thickness_exponent"
range = [0.25, 4.0]
step = 0.1
fine_step = 0.01
question = "Turn the right object until it looks like the left one."

[[blocks]]
id = "j"
task = "staircase"
stimuli = ["target"]
knob = "thickness_exponent"
question = "Which looks more translucent?"
trial = "pair"

[[blocks.staircases]]
id = "a"
method = "updown"
start = 0.5
step_sizes = [0.1, 0.05]
n_trials = 3
max_trials = 4

[[blocks.staircases]]
id = "b"
method = "updown"
start = 0.8
step_sizes = [0.2, 0.1]
n_trials = 3
max_trials = 4
)toml";

inline study::Protocol matching_protocol() {
    return study::parse_protocol(kMatchingProtocol, "matching.toml");
}

inline study::Protocol choice_protocol() {
    return study::parse_protocol(kChoiceProtocol, "choices.toml");
}

inline study::Protocol small_protocol() {
    return study::parse_protocol(kSmallProtocol, "small.toml");
}

// The small protocol with mixed scales: 'translucent' keeps 7 points, 'realistic' gets 5
// (the catch trial then asks for 5, the most every scale has).
inline std::string mixed_scale_protocol_text() {
    const std::string text = kSmallProtocol;
    const std::string realistic = "text = \"The object looks realistic.\"\n";
    const size_t question = text.find(realistic) + realistic.size();
    const size_t expected = text.find("expected = 7");
    return text.substr(0, question) +
           "labels = [\"not at all\", \"\", \"\", \"\", \"fully\"]\n" +
           text.substr(question, expected - question) + "expected = 5" +
           text.substr(expected + 12);
}
inline study::Protocol mixed_scale_protocol() {
    return study::parse_protocol(mixed_scale_protocol_text(), "mixed.toml");
}

// Deterministic rating for (trial position, question index): lets tests recompute
// expected exports independently of the database.
inline int rating_for(int position, int question) {
    return 1 + (position * 3 + question * 2) % 7;
}

// Deterministic choice (1 or 2) of a forced-choice trial at `position`.
inline int choice_for(int position) { return 1 + (position * 5 + 1) % 3 % 2; }

// Deterministic answers of adjust and staircase trials (issue 31): an adjust trial's
// confirmed value and its three changes on the way (the last reaches it), a staircase
// trial's delta.
inline double final_value_for(int position) { return 0.25 + 0.125 * (position % 20); }
inline std::vector<study::Adjustment> adjustments_for(int position, int64_t onset_ns) {
    const double final_value = final_value_for(position);
    return {{final_value + 0.5, onset_ns + 250'000'000LL + position, "key"},
            {final_value + 0.03125, onset_ns + 600'000'123LL, "fine_key"},
            {final_value, onset_ns + 1'000'000'000LL, "drag"}};
}
inline double intensity_for(int position) { return 0.0625 * (1 + position % 7); }

inline study::TrialOutcome outcome_for(const study::Protocol& p, const study::TrialRow& t,
                                       int catch_rating = 7) {
    study::TrialOutcome o;
    o.onset_ns = 1000000LL * (t.position + 1);
    o.confirm_ns = o.onset_ns + 900000000LL;
    if (t.task != study::Task::rating) {
        study::Response r;
        r.question = p.find_block(t.block)->question_id;
        r.rating = t.is_catch && t.expected > 0 ? t.expected : choice_for(t.position);
        r.rt_ms = 700.0 + t.position;
        r.first_choice_ns = o.onset_ns + 100;
        r.final_choice_ns = o.onset_ns + 200;
        if (t.task == study::Task::adjust) {
            r.rating = 1;  // confirmed
            r.changes = 3;
            o.final_value = final_value_for(t.position);
            o.adjustments = adjustments_for(t.position, o.onset_ns);
        } else if (t.task == study::Task::staircase) {
            o.intensity = intensity_for(t.position);
        }
        o.responses.push_back(r);
        return o;
    }
    for (int q = 0; q < static_cast<int>(p.questions.size()); ++q) {
        study::Response r;
        r.question = p.questions[q].id;
        r.rating = t.is_catch ? catch_rating : rating_for(t.position, q);
        r.rt_ms = 500.0 + 100 * q;
        r.changes = q;
        r.first_choice_ns = o.onset_ns + 100;
        r.final_choice_ns = o.onset_ns + 200;
        o.responses.push_back(r);
    }
    return o;
}

// Starts a session for `code` and answers every trial; returns the session id.
inline int64_t run_full_session(study::Store& store, const study::Protocol& p,
                                const std::string& code, uint64_t seed,
                                int catch_rating = 7) {
    const int64_t study_id = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study_id, code, &number);
    study::SessionRow s = store.create_session(
        study_id, pid, study::plan_trials(p, seed, number), seed, {});
    for (const study::TrialRow& t : store.trials(s.id))
        store.record_trial(s.id, t.id, outcome_for(p, t, catch_rating));
    store.set_status(s.id, "completed", true);
    return s.id;
}

}  // namespace lucent::test
