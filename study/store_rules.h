#pragma once
// The rules every study store keeps, whatever its SQL. A backend reads the facts a rule
// needs inside its own transaction (with the locks its database takes), asks the rule,
// and only then writes; so SQLite and PostgreSQL refuse the same things with the same
// one-line StoreError, and a backend is its SQL.
#include <cstdint>
#include <string>

#include "study/question_scales.h"
#include "study/store_types.h"

namespace lucent::study {

// What a store holds about a trial it is asked to record.
struct TrialAnswerFacts {
    bool part_of_session = false;  // a planned trial of the session named
    bool answered = false;         // ratings are held for it already (or journaled)
};

// A trial's answer is recorded once, for a planned trial of its session, with exactly
// one rating for each question the study asks, each within its question's scale
// (`points`). `store` names the store in messages. Throws StoreError.
void check_trial_answer(const std::string& store, int64_t session_id, int64_t trial_id,
                        const TrialAnswerFacts& facts, const QuestionPoints& points,
                        const TrialOutcome& outcome);
// The refusal of a second answer to `trial_id`, for a store that finds the first one
// only later (a server holding ratings for a journaled trial).
[[noreturn]] void refuse_second_answer(const std::string& store, int64_t trial_id);

// A completed session is final: setting any other status on it throws StoreError.
void check_status_change(const std::string& store, const std::string& session_uuid,
                         const std::string& current_status,
                         const std::string& new_status);

}  // namespace lucent::study
