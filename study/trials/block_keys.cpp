#include "study/trials/block_keys.h"

#include <string>
#include <variant>
#include <vector>

#include "renderer/techniques/registry.h"
#include "study/trials/table_reader.h"
#include "study/trials/trial_kind.h"

namespace lucent::study {

void check_stimulus_ref(const Protocol& p, TableReader& r, const std::string& key,
                        const std::string& id) {
    if (!p.find_stimulus(id))
        r.fail(r.raw().get(key), key, "no stimulus with id '" + id + "'");
}

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
        if (!other.task->rated_on_questions() && other.question_id == b.question_id)
            r.fail(
                r.raw().get("question_id"), "question_id",
                "'" + b.question_id + "' is already block '" + other.id + "'s question");
}

void read_presentation(TableReader& r, Block& b, int pictures, bool answers_are_pairs) {
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
        if (answers_are_pairs)
            b.labels = {"first pair", "second pair"};
        else if (pictures == 3)
            b.labels = sequence ? std::vector<std::string>{"first", "second", "third"}
                                : std::vector<std::string>{"left", "middle", "right"};
        else
            b.labels = sequence ? std::vector<std::string>{"first", "second"}
                                : std::vector<std::string>{"left", "right"};
    }
    const size_t answers = answers_are_pairs ? 2 : static_cast<size_t>(pictures);
    if (b.labels.size() != answers)
        r.fail(r.raw().get("labels"), "labels",
               answers == 2 ? "needs exactly two answers"
                            : "needs exactly " + std::to_string(answers) + " answers");
    b.duration_ms = r.integer("duration_ms", 1000, 50, 60000);
    b.blank_ms = r.integer("blank_ms", 500, 0, 60000);
}

Knob block_knob(const Protocol& p, TableReader& r, const Block& b,
                const std::string& stimulus, const std::string& key) {
    const Stimulus* s = p.find_stimulus(stimulus);
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

double knob_value_of(const Protocol& p, const std::string& stimulus, const Knob& knob) {
    if (const std::optional<double> v = p.numeric_parameter(stimulus, knob.name))
        return *v;
    return std::get<double>(knob.default_value);
}

}  // namespace lucent::study
