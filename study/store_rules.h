#pragma once
// The rules every study store keeps, whatever its SQL. A backend reads the facts a rule
// needs inside its own transaction (with the locks its database takes), asks the rule,
// and only then writes; so SQLite and PostgreSQL refuse the same things with the same
// one-line StoreError, and a backend is its SQL.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "study/question_scales.h"
#include "study/store_types.h"

namespace lucent::study {

struct TrialPlan;
struct PlannedTrial;

// A new session's row as both backends fill it before the insert (the id and the
// participant's code come from the store): running, in the plan's cell.
SessionRow new_session_row(const std::string& uuid, int64_t participant_id, uint64_t seed,
                           const TrialPlan& plan);
// sessions.block_order: the plan's block names, comma-separated.
std::string block_order_text(const TrialPlan& plan);

// What a store holds about a trial it is asked to record.
struct TrialAnswerFacts {
    bool part_of_session = false;  // a planned trial of the session named
    bool answered = false;         // ratings are held for it already (or journaled)
    Task kind = Task::rating;      // trials.kind (schema 7; before: task, or rating)
    bool skipped = false;          // a staircase slot skipped: its procedure finished
    std::string staircase;         // a staircase slot's procedure (trials.staircase)
};

// A trial's answer is recorded once, for a planned trial of its session that was not
// skipped, with exactly one rating for each question the study asks, each within its
// question's scale (`points`). What the outcome carries besides follows the trial's
// kind (schema 7): an adjust trial a finite final_value and its adjustments (finite
// values, times in order, inputs key, fine_key, wheel or drag; none when the start was
// confirmed as it was); a staircase trial a finite intensity, and finishes_staircase
// only when it has a procedure; every other trial none of these. `store` names the
// store in messages. Throws StoreError (one line naming the store and the trial).
void check_trial_answer(const std::string& store, int64_t session_id, int64_t trial_id,
                        const TrialAnswerFacts& facts, const QuestionPoints& points,
                        const TrialOutcome& outcome);
// The outcome's columns only some kinds carry (schema 7), for TrialKind::check_outcome:
// those a kind does not carry are refused (StoreError: "<where> is a rating trial but
// carries a final value").
struct OutcomeColumns {
    bool final_value_and_adjustments = false;  // adjust
    bool intensity = false;                    // staircase (and finishes_staircase)
};
void refuse_outcome_columns(const std::string& where, Task kind,
                            const TrialOutcome& outcome, OutcomeColumns carries);
// The refusal of a second answer to `trial_id`, for a store that finds the first one
// only later (a server holding ratings for a journaled trial).
[[noreturn]] void refuse_second_answer(const std::string& store, int64_t trial_id);
// The refusal of an answer to a skipped staircase slot, for a store that finds the skip
// only later (a server where another answer finished the procedure).
[[noreturn]] void refuse_skipped_trial(const std::string& store, int64_t trial_id);

// A completed session is final: setting any other status on it throws StoreError.
void check_status_change(const std::string& store, const std::string& session_uuid,
                         const std::string& current_status,
                         const std::string& new_status);

// A later session, or a database merged in, shows each stimulus as the first session
// recorded it: "" when `a` and `b` are equal, else "stimulus 'ID': parameter 'NAME' is A
// in <a_name> but B in <b_name>" for the first difference (technique, mesh, mesh_hash or
// a knob value).
std::string resolved_difference(const std::string& stimulus, const ResolvedStimulus& a,
                                const std::string& a_name, const ResolvedStimulus& b,
                                const std::string& b_name);
// A provenance row as stored.
ResolvedStimulus resolved_of(const StimulusProvenance& p);
// One word for a segment's pictures: the common source, "mixed", or nullopt when unknown.
std::optional<std::string> segment_source(const std::vector<StimulusProvenance>& stimuli);
// session_segments.series_set: SHA-256 of the pictures' ids and content hashes, in id
// order (one value per distinct set of files), or nullopt when there are none.
std::optional<std::string> series_set_hash(
    const std::vector<StimulusProvenance>& pictures);

// trials.shown: a forced choice's stimulus keys in screen order, space-separated (keys
// hold no whitespace: the protocol refuses them in choice blocks); "" for a rating.
std::string shown_text(const std::vector<std::string>& shown);
std::vector<std::string> shown_from_text(const std::string& text);
// The columns of a planned trial as both backends write them: trials.shown (NULL for a
// rating) and trials.expected_rating of a catch trial (NULL for an identical pair,
// which has no right answer) or of a staircase slot (the comparison's place, schema 7);
// NULL for every other trial.
std::optional<std::string> shown_column(const PlannedTrial& trial);
std::optional<int> expected_rating_column(const PlannedTrial& trial);
// trials.task as read back (NULL: a rating, planned before schema 6). From schema 7
// on readers read trials.kind, which the migration fills: read
// coalesce(t.kind, t.task) and give it here. A kind this build does not know (a
// build with another registry wrote it) throws StoreError naming it.
Task task_column(const std::optional<std::string>& text);
// The kind columns of a planned trial as both backends write them (schema 7):
// trials.kind, its task's name; trials.task the same for the tasks its CHECK knows
// (rating, pair, triad, quadruple; older readers see those as before), NULL for every
// other kind (adjust, staircase, a registered one).
std::string kind_column(const PlannedTrial& trial);
std::optional<std::string> legacy_task_column(const PlannedTrial& trial);
// trials.staircase: a staircase slot's procedure; NULL for every other trial.
std::optional<std::string> staircase_column(const PlannedTrial& trial);

// A participant's number: a lab code's trailing digits (-1 when none or over 9 digits).
int participant_number_from_code(const std::string& code);
// Online allocation (enrol_online): given each cell's completed + active sessions, the
// cell with the fewest (ties: the first from number mod cells) and the allocation text
// sessions.allocation records.
std::pair<int, std::string> online_cell(const std::vector<int64_t>& counts, int number,
                                        const std::string& active_since_utc);

}  // namespace lucent::study
