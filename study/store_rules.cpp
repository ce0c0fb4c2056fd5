#include "study/store_rules.h"

#include <set>

namespace lucent::study {

void refuse_second_answer(const std::string& store, int64_t trial_id) {
    throw StoreError(store + ": trial " + std::to_string(trial_id) +
                     " already has ratings; refusing to record it twice");
}

void check_trial_answer(const std::string& store, int64_t session_id, int64_t trial_id,
                        const TrialAnswerFacts& facts, const QuestionPoints& points,
                        const TrialOutcome& outcome) {
    const std::string where = store + ": trial " + std::to_string(trial_id);
    if (!facts.part_of_session)
        throw StoreError(where + " is not part of session " + std::to_string(session_id));
    if (facts.answered) refuse_second_answer(store, trial_id);
    std::set<std::string> questions;
    for (const Response& r : outcome.responses) {
        check_rating_on_scale(points, r.question, r.rating, where);
        if (!questions.insert(r.question).second)
            throw StoreError(where + " rates question '" + r.question + "' twice");
    }
    if (outcome.responses.size() != points.size())
        throw StoreError(where + " has " + std::to_string(outcome.responses.size()) +
                         " ratings for " + std::to_string(points.size()) + " questions");
}

void check_status_change(const std::string& store, const std::string& session_uuid,
                         const std::string& current_status,
                         const std::string& new_status) {
    if (current_status == "completed" && new_status != "completed")
        throw StoreError(store + ": session " + session_uuid +
                         " is completed; refusing to set it " + new_status);
}

}  // namespace lucent::study
