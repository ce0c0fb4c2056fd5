#pragma once
// A browser's answer to a trial: its events checked and bounded before any is replayed,
// then replayed on a copy of the session flow as the lab's RatingInput takes keys and
// clicks, so an answer online is scored exactly as one in the lab.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/session/session_flow.h"
#include "study/store_types.h"

namespace lucent::study {

// One input event of an answer, checked, as the lab's RatingInput takes it.
struct AnswerEvent {
    enum class Kind { Key, Point, Next } kind;
    Key key = Key::Enter;
    int digit = 0, question = 0, value = 0;
    int64_t t_ns = 0;
};

// The trial an answer names must be the one on screen: 404 when it is none of the
// session's, 409 when answered already or not shown (RequestError).
void check_trial_on_screen(const SessionFlow& flow, const std::vector<TrialRow>& trials,
                           const std::string& trial_uuid);
// The answer's `events`, at most kMaxEventsPerAnswer, each checked: a key the scales or
// the lab know, a rating inside its question's scale, or Next.
std::vector<AnswerEvent> events_of(const nlohmann::json& body,
                                   const std::vector<Question>& questions);
// Replayed on a copy: the blank gives way to the picture at its onset, then the keys
// and clicks as the lab's RatingInput takes them; the copy commits the trial. 400 when
// the events do not rate every question and confirm it.
SessionFlow replayed(const SessionFlow& flow, double onset_ms,
                     const std::vector<AnswerEvent>& replay, int inter_trial_ms);

}  // namespace lucent::study
