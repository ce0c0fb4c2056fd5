#include "study/serve/answer_events.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <utility>

#include "study/serve/request_fields.h"
#include "study/serve/web_study.h"  // kMaxEventsPerAnswer

namespace lucent::study {

using nlohmann::json;

namespace {

// The browser's name of an arrow key or Enter, as the flow's key; nullopt for any other.
std::optional<Key> arrow_or_enter(const std::string& key) {
    if (key == "ArrowLeft") return Key::Left;
    if (key == "ArrowRight") return Key::Right;
    if (key == "ArrowUp") return Key::Up;
    if (key == "ArrowDown") return Key::Down;
    if (key == "Enter") return Key::Enter;
    return std::nullopt;
}

// One of a rating's events, checked: a key the scales (at most `max_points`) or the
// lab know, a rating inside its question's scale, or Next.
AnswerEvent rating_event_of(const json& e, const std::string& type,
                            const std::vector<Question>& questions, int max_points) {
    AnswerEvent ev{AnswerEvent::Kind::Key};
    if (type == "key") {
        const std::string key = text_field(e, "key", 16, true);
        if (key.size() == 1 && key[0] >= '1' && key[0] <= '9') {
            ev.key = Key::Digit;
            ev.digit = key[0] - '0';
            if (ev.digit > max_points)
                throw RequestError(400, "key '" + key + "' is outside every scale (1.." +
                                            std::to_string(max_points) + ")");
        } else if (const std::optional<Key> k = arrow_or_enter(key)) {
            ev.key = *k;
        } else {
            throw RequestError(400, "unknown key '" + one_line(key) + "'");
        }
    } else if (type == "point") {
        ev.kind = AnswerEvent::Kind::Point;
        const double q = *number_field(e, "question", 0, 1e6, true);
        if (q != std::floor(q) || q >= static_cast<double>(questions.size()))
            throw RequestError(400, "question index " + json(q).dump() +
                                        " is not one of the " +
                                        std::to_string(questions.size()) + " questions");
        ev.question = static_cast<int>(q);
        const Question& question = questions[ev.question];
        const json* v = field(e, "value");
        if (!v || !v->is_number_integer() || v->get<int64_t>() < 1 ||
            v->get<int64_t>() > question.points())
            throw RequestError(400, "rating " + (v ? v->dump() : std::string("(none)")) +
                                        " is outside 1.." +
                                        std::to_string(question.points()) +
                                        " of question '" + question.id + "'");
        ev.value = static_cast<int>(v->get<int64_t>());
    } else if (type == "next") {
        ev.kind = AnswerEvent::Kind::Next;
    } else if (type == "choice") {
        throw RequestError(400,
                           "field 'type': a 'choice' event answers a forced choice; this "
                           "trial is a rating");
    } else {
        throw RequestError(400, "unknown event type '" + one_line(type) + "'");
    }
    return ev;
}

// One of a forced choice's events, checked: ArrowLeft, ArrowRight, 1..alternatives
// (pick), Enter (confirm), or a click on an alternative (pick and confirm).
AnswerEvent choice_event_of(const json& e, const std::string& type, Task task,
                            int alternatives) {
    AnswerEvent ev{AnswerEvent::Kind::Key};
    const std::string digits = alternatives == 3 ? "1, 2, 3" : "1, 2";
    if (type == "key") {
        const std::string key = text_field(e, "key", 16, true);
        if (key.size() == 1 && key[0] >= '1' && key[0] < '1' + alternatives) {
            ev.key = Key::Digit;
            ev.digit = key[0] - '0';
        } else if (key == "Enter") {
            ev.key = Key::Enter;
        } else if (key == "ArrowLeft") {
            ev.key = Key::Left;
        } else if (key == "ArrowRight") {
            ev.key = Key::Right;
        } else {
            throw RequestError(400, "field 'key': '" + one_line(key) +
                                        "' does not answer a forced choice (ArrowLeft, "
                                        "ArrowRight, " +
                                        digits + ", Enter)");
        }
    } else if (type == "choice") {
        ev.kind = AnswerEvent::Kind::Choice;
        const json* a = field(e, "alternative");
        if (!a || !a->is_number_integer() || a->get<int64_t>() < 1 ||
            a->get<int64_t>() > alternatives)
            throw RequestError(
                400, "field 'alternative' must be " +
                         std::string(alternatives == 3 ? "1, 2 or 3" : "1 or 2") +
                         ", not " + (a ? one_line(to_text(*a)) : std::string("none")));
        ev.alternative = static_cast<int>(a->get<int64_t>());
    } else if (type == "point" || type == "next") {
        throw RequestError(400, "field 'type': a '" + type +
                                    "' event rates a question; this trial is a forced "
                                    "choice (" +
                                    task_name(task) + ")");
    } else {
        throw RequestError(400, "unknown event type '" + one_line(type) + "'");
    }
    return ev;
}

// One of an adjustment's events, checked: an arrow (Shift: the fine step) or Enter, the
// wheel's notches, a drag across the match. Bounded so that no NaN, infinity or absurd
// move reaches AdjustInput (which would ignore or clamp them silently).
AnswerEvent adjust_event_of(const json& e, const std::string& type) {
    AnswerEvent ev{AnswerEvent::Kind::Key};
    if (type == "key") {
        const std::string key = text_field(e, "key", 16, true);
        if (const std::optional<Key> k = arrow_or_enter(key)) {
            ev.key = *k;
        } else {
            throw RequestError(400, "field 'key': '" + one_line(key) +
                                        "' does not adjust the match (ArrowLeft, "
                                        "ArrowRight, ArrowUp, ArrowDown, Enter)");
        }
        if (const json* shift = field(e, "shift")) {
            if (!shift->is_boolean())
                throw RequestError(400, "field 'shift' must be true or false");
            ev.shift = shift->get<bool>();
        }
    } else if (type == "wheel") {
        ev.kind = AnswerEvent::Kind::Wheel;
        ev.notches = *number_field(e, "notches", -100, 100, true);
    } else if (type == "drag") {
        ev.kind = AnswerEvent::Kind::Drag;
        ev.dx = *number_field(e, "dx", -1e5, 1e5, true);
        // At least a pixel: a match narrower is no match shown (and dx / width stays
        // finite).
        ev.width = *number_field(e, "width", 1, 1e5, true);
    } else if (type == "choice" || type == "point" || type == "next") {
        throw RequestError(400, "field 'type': a '" + type + "' event answers a " +
                                    (type == "choice" ? "forced choice" : "rating") +
                                    "; this trial is an adjustment");
    } else {
        throw RequestError(400, "unknown event type '" + one_line(type) + "'");
    }
    return ev;
}

AnswerEvent event_of(const json& e, const std::vector<Question>& questions,
                     int max_points, Task task, int alternatives) {
    if (!e.is_object()) throw RequestError(400, "each event must be an object");
    const int64_t t_ns = ms_to_ns(*number_field(e, "t_ms", 0, kMaxPageMs, true));
    const std::string type = text_field(e, "type", 16, true);
    const TrialScreen screen = task->screen();
    if (screen != TrialScreen::adjust) {
        // An adjustment's input on any other trial: refused, never ignored.
        const std::string this_trial =
            screen == TrialScreen::scales
                ? std::string(task == Task::rating
                                  ? "a rating"
                                  : std::string("a rating (") + task_name(task) + ")")
                : std::string("a forced choice (") + task_name(task) + ")";
        if (type == "wheel" || type == "drag")
            throw RequestError(400, "field 'type': a '" + type +
                                        "' event adjusts a match; this trial is " +
                                        this_trial);
        if (const json* shift = field(e, "shift"); shift && *shift != json(false))
            throw RequestError(
                400,
                "field 'shift' is only for an adjustment's arrows; this "
                "trial is " +
                    std::string(screen == TrialScreen::scales ? "a rating"
                                                              : "a forced choice"));
    }
    AnswerEvent ev;
    switch (screen) {
        case TrialScreen::scales:
            ev = rating_event_of(e, type, questions, max_points);
            break;
        case TrialScreen::adjust:
            ev = adjust_event_of(e, type);
            break;
        case TrialScreen::choice:
        case TrialScreen::staircase:
            ev = choice_event_of(e, type, task, alternatives);
            break;
    }
    ev.t_ns = t_ns;
    return ev;
}

std::string milliseconds(double ms) {
    char out[32];
    std::snprintf(out, sizeof out, "%.1f", ms);
    return out;
}

const char* phase_name(ChoicePhase phase) {
    switch (phase) {
        case ChoicePhase::First:
            return "first part";
        case ChoicePhase::Gap:
            return "blank";
        case ChoicePhase::Second:
            return "second part";
        case ChoicePhase::Answer:
            return "answer screen";
    }
    return "answer screen";
}

}  // namespace

void check_trial_on_screen(const SessionFlow& flow, const std::vector<TrialRow>& trials,
                           const std::string& trial_uuid) {
    const TrialRow* current = flow.trial();
    if (!current || current->uuid != trial_uuid) {
        const auto it =
            std::find_if(trials.begin(), trials.end(),
                         [&](const TrialRow& t) { return t.uuid == trial_uuid; });
        if (it == trials.end())
            throw RequestError(
                404, "trial '" + trial_uuid + "' is not one of this session's trials");
        if (it->answered)
            throw RequestError(409, "trial " + std::to_string(it->position + 1) +
                                        " is already answered");
        throw RequestError(409, "trial " + std::to_string(it->position + 1) +
                                    " is not the one on screen");
    }
}

std::vector<AnswerEvent> events_of(const json& body,
                                   const std::vector<Question>& questions, Task task,
                                   int alternatives) {
    const json* events = field(body, "events");
    if (!events || !events->is_array())
        throw RequestError(400, "field 'events' must be an array");
    if (events->size() > kMaxEventsPerAnswer)
        throw RequestError(
            400, "more than " + std::to_string(kMaxEventsPerAnswer) + " events");

    // Every event checked before any is replayed.
    int max_points = 0;
    for (const Question& q : questions) max_points = std::max(max_points, q.points());
    std::vector<AnswerEvent> replay;
    for (const json& e : *events)
        replay.push_back(event_of(e, questions, max_points, task, alternatives));
    return replay;
}

std::optional<SequenceOnsets> sequence_onsets_of(const json& body, bool sequential) {
    const json* onsets = field(body, "phase_onsets_ms");
    if (!sequential) {
        if (onsets)
            throw RequestError(400,
                               "field 'phase_onsets_ms' is only for a trial shown in "
                               "sequence");
        return std::nullopt;
    }
    if (!onsets || !onsets->is_object())
        throw RequestError(400,
                           "field 'phase_onsets_ms' ({\"gap\", \"second\", \"answer\"}) "
                           "is required for a trial shown in sequence");
    SequenceOnsets out;
    out.gap_ms = *number_field(*onsets, "gap", 0, kMaxPageMs, true);
    out.second_ms = *number_field(*onsets, "second", 0, kMaxPageMs, true);
    out.answer_ms = *number_field(*onsets, "answer", 0, kMaxPageMs, true);
    return out;
}

SessionFlow replayed(const SessionFlow& flow, double onset_ms,
                     const std::optional<SequenceOnsets>& sequence,
                     const std::vector<AnswerEvent>& replay, int inter_trial_ms) {
    SessionFlow next = flow;
    const int64_t onset_ns = ms_to_ns(onset_ms);
    next.tick(onset_ns);
    if (next.screen() != Screen::Trial)
        throw RequestError(400, "the picture was shown before the " +
                                    std::to_string(inter_trial_ms) + " ms blank ended");
    next.presented(next.serial(), onset_ns);
    if (sequence) {
        // Each part as the page showed it; the flow moves on only once the part before
        // has been on the display for its duration (the lab's rule, from its frames).
        const std::pair<ChoicePhase, double> parts[] = {
            {ChoicePhase::Gap, sequence->gap_ms},
            {ChoicePhase::Second, sequence->second_ms},
            {ChoicePhase::Answer, sequence->answer_ms}};
        const Block* block = next.block();
        double before_ms = onset_ms;
        for (const auto& [phase, at_ms] : parts) {
            const ChoicePhase previous = *next.choice_phase();
            const int64_t at_ns = ms_to_ns(at_ms);
            next.tick(at_ns);
            if (next.choice_phase() != phase) {
                const int needed =
                    previous == ChoicePhase::Gap ? block->blank_ms : block->duration_ms;
                throw RequestError(
                    400, "field 'phase_onsets_ms." +
                             std::string(phase == ChoicePhase::Gap      ? "gap"
                                         : phase == ChoicePhase::Second ? "second"
                                                                        : "answer") +
                             "': the " + phase_name(phase) + " came " +
                             milliseconds(at_ms - before_ms) + " ms after the " +
                             phase_name(previous) + ", which is shown for " +
                             std::to_string(needed) + " ms");
            }
            next.presented(next.serial(), at_ns);
            before_ms = at_ms;
        }
    }
    const bool choice = next.choice_phase().has_value();
    const bool adjust = next.adjustment() != nullptr;
    const size_t answered_before = next.answered_trials();
    for (const AnswerEvent& ev : replay) {
        if (next.answered_trials() != answered_before)
            break;  // confirmed: the rest is late
        switch (ev.kind) {
            case AnswerEvent::Kind::Key:
                next.key({ev.key, ev.digit, ev.t_ns, ev.shift});
                break;
            case AnswerEvent::Kind::Point:
                next.click_point(ev.question, ev.value, ev.t_ns);
                break;
            case AnswerEvent::Kind::Next:
                next.click_next(ev.t_ns);
                break;
            case AnswerEvent::Kind::Choice:
                next.click_choice(ev.alternative, ev.t_ns);
                break;
            case AnswerEvent::Kind::Wheel:
                next.wheel(ev.notches, ev.t_ns);
                break;
            case AnswerEvent::Kind::Drag:
                next.drag(ev.dx, ev.width, ev.t_ns);
                break;
        }
    }
    if (next.answered_trials() == answered_before)
        throw RequestError(
            400, adjust   ? "the events do not confirm the match (Enter) after the "
                            "pictures' onset"
                 : choice ? "the events do not choose an alternative and confirm "
                            "it (Enter or a click) after the answer screen's onset"
                          : "the events do not rate every question and confirm it "
                            "(Enter or Next) after the picture's onset");
    return next;
}

}  // namespace lucent::study
