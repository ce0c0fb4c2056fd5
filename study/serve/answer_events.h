#pragma once
// A browser's answer to a trial: its events checked and bounded before any is replayed,
// then replayed on a copy of the session flow as the lab's RatingInput takes keys and
// clicks, so an answer online is scored exactly as one in the lab. A forced choice
// (pair, triad, quadruple) takes its own events (Left/Right, 1/2, Enter, a click on an
// alternative); one shown in sequence also carries when each part reached the display.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/session/session_flow.h"
#include "study/store_types.h"

namespace lucent::study {

// One input event of an answer, checked, as the lab's RatingInput (an adjustment: its
// AdjustInput) takes it.
struct AnswerEvent {
    enum class Kind { Key, Point, Next, Choice, Wheel, Drag } kind;
    Key key = Key::Enter;
    bool shift = false;  // Key on an adjustment: the fine step
    int digit = 0, question = 0, value = 0;
    int alternative = 0;       // Choice: 1..the block's answers
    double notches = 0;        // Wheel: positive up
    double dx = 0, width = 0;  // Drag: pixels across a match `width` wide
    int64_t t_ns = 0;
};

// The trial an answer names must be the one on screen: 404 when it is none of the
// session's, 409 when answered already or not shown (RequestError).
void check_trial_on_screen(const SessionFlow& flow, const std::vector<TrialRow>& trials,
                           const std::string& trial_uuid);
// The answer's `events`, at most kMaxEventsPerAnswer, each checked against the trial's
// task. A rating: a key the scales or the lab know, a rating inside its question's
// scale, or Next. A forced choice (`alternatives`: 2, 3 for an odd-one-out staircase):
// ArrowLeft, ArrowRight, 1..alternatives, Enter, or a click on an alternative. An
// adjustment: an arrow (with `shift`: the fine step) or Enter, wheel notches
// (|notches| <= 100), a drag (|dx| <= 100000 px across a match 1 <= width <= 100000 px
// wide). An event of another kind of trial is a 400 naming the field.
std::vector<AnswerEvent> events_of(const nlohmann::json& body,
                                   const std::vector<Question>& questions, Task task,
                                   int alternatives);

// When each part of a forced choice shown in sequence reached the display (the page's
// performance.now(), ms): the blank after the first part, the second part, and the
// answer screen. The first part's is the trial's onset (`onset_ms`).
struct SequenceOnsets {
    double gap_ms = 0, second_ms = 0, answer_ms = 0;
};
// The answer's `phase_onsets_ms` ({"gap", "second", "answer"}): required for a trial
// shown in sequence, refused (400) on any other.
std::optional<SequenceOnsets> sequence_onsets_of(const nlohmann::json& body,
                                                 bool sequential);

// Replayed on a copy: the blank gives way to the picture at its onset (a sequence's
// parts at their onsets, each refused (400) when it came before the part before had
// been on the display for its duration), then the keys and clicks as the lab's
// RatingInput (an adjustment: AdjustInput) takes them; the copy commits the trial. 400
// when the events do not rate every question (choose an alternative) and confirm it.
SessionFlow replayed(const SessionFlow& flow, double onset_ms,
                     const std::optional<SequenceOnsets>& sequence,
                     const std::vector<AnswerEvent>& replay, int inter_trial_ms);

}  // namespace lucent::study
