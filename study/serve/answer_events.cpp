#include "study/serve/answer_events.h"

#include <algorithm>
#include <cmath>

#include "study/serve/request_fields.h"
#include "study/serve/web_study.h"  // kMaxEventsPerAnswer

namespace lucent::study {

using nlohmann::json;

namespace {

// One of an answer's events, checked: a key the scales (at most `max_points`) or the
// lab know, a rating inside its question's scale, or Next.
AnswerEvent event_of(const json& e, const std::vector<Question>& questions,
                     int max_points) {
    if (!e.is_object()) throw RequestError(400, "each event must be an object");
    AnswerEvent ev{AnswerEvent::Kind::Key};
    ev.t_ns = ms_to_ns(*number_field(e, "t_ms", 0, kMaxPageMs, true));
    const std::string type = text_field(e, "type", 16, true);
    if (type == "key") {
        const std::string key = text_field(e, "key", 16, true);
        if (key.size() == 1 && key[0] >= '1' && key[0] <= '9') {
            ev.key = Key::Digit;
            ev.digit = key[0] - '0';
            if (ev.digit > max_points)
                throw RequestError(400, "key '" + key + "' is outside every scale (1.." +
                                            std::to_string(max_points) + ")");
        } else if (key == "Enter") {
            ev.key = Key::Enter;
        } else if (key == "ArrowLeft") {
            ev.key = Key::Left;
        } else if (key == "ArrowRight") {
            ev.key = Key::Right;
        } else if (key == "ArrowUp") {
            ev.key = Key::Up;
        } else if (key == "ArrowDown") {
            ev.key = Key::Down;
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
    } else {
        throw RequestError(400, "unknown event type '" + one_line(type) + "'");
    }
    return ev;
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
                                   const std::vector<Question>& questions) {
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
    for (const json& e : *events) replay.push_back(event_of(e, questions, max_points));
    return replay;
}

SessionFlow replayed(const SessionFlow& flow, double onset_ms,
                     const std::vector<AnswerEvent>& replay, int inter_trial_ms) {
    SessionFlow next = flow;
    const int64_t onset_ns = ms_to_ns(onset_ms);
    next.tick(onset_ns);
    if (next.screen() != Screen::Trial)
        throw RequestError(400, "the picture was shown before the " +
                                    std::to_string(inter_trial_ms) + " ms blank ended");
    next.presented(next.serial(), onset_ns);
    const size_t answered_before = next.answered_trials();
    for (const AnswerEvent& ev : replay) {
        if (next.answered_trials() != answered_before)
            break;  // confirmed: the rest is late
        switch (ev.kind) {
            case AnswerEvent::Kind::Key:
                next.key({ev.key, ev.digit, ev.t_ns});
                break;
            case AnswerEvent::Kind::Point:
                next.click_point(ev.question, ev.value, ev.t_ns);
                break;
            case AnswerEvent::Kind::Next:
                next.click_next(ev.t_ns);
                break;
        }
    }
    if (next.answered_trials() == answered_before)
        throw RequestError(400,
                           "the events do not rate every question and confirm it "
                           "(Enter or Next) after the picture's onset");
    return next;
}

}  // namespace lucent::study
