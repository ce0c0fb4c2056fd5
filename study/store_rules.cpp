#include "study/store_rules.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include "study/sha256.h"
#include "study/trial_plan.h"

namespace lucent::study {

void refuse_second_answer(const std::string& store, int64_t trial_id) {
    throw StoreError(store + ": trial " + std::to_string(trial_id) +
                     " already has ratings; refusing to record it twice");
}

void refuse_skipped_trial(const std::string& store, int64_t trial_id) {
    throw StoreError(store + ": trial " + std::to_string(trial_id) +
                     " was skipped (its staircase had finished); refusing to record it");
}

void refuse_outcome_columns(const std::string& where, Task kind,
                            const TrialOutcome& outcome, OutcomeColumns carries) {
    const std::string name = task_name(kind);
    const std::string a_kind =
        std::string(name.find_first_of("aeiou") == 0 ? "an " : "a ") + name + " trial";
    if (!carries.final_value_and_adjustments) {
        if (outcome.final_value)
            throw StoreError(where + " is " + a_kind + " but carries a final value");
        if (!outcome.adjustments.empty())
            throw StoreError(where + " is " + a_kind + " but carries adjustments");
    }
    if (!carries.intensity) {
        if (outcome.intensity)
            throw StoreError(where + " is " + a_kind + " but carries an intensity");
        if (outcome.finishes_staircase)
            throw StoreError(where + " is " + a_kind + " but finishes a staircase");
    }
}

void TrialKind::check_outcome(const std::string& where, const TrialAnswerFacts& facts,
                              const TrialOutcome& outcome) const {
    refuse_outcome_columns(where, facts.kind, outcome, {});
}

void check_trial_answer(const std::string& store, int64_t session_id, int64_t trial_id,
                        const TrialAnswerFacts& facts, const QuestionPoints& points,
                        const TrialOutcome& outcome) {
    const std::string where = store + ": trial " + std::to_string(trial_id);
    if (!facts.part_of_session)
        throw StoreError(where + " is not part of session " + std::to_string(session_id));
    if (facts.answered) refuse_second_answer(store, trial_id);
    if (facts.skipped) refuse_skipped_trial(store, trial_id);
    std::set<std::string> questions;
    for (const Response& r : outcome.responses) {
        check_rating_on_scale(points, r.question, r.rating, where);
        if (!questions.insert(r.question).second)
            throw StoreError(where + " rates question '" + r.question + "' twice");
    }
    if (outcome.responses.size() != points.size())
        throw StoreError(where + " has " + std::to_string(outcome.responses.size()) +
                         " ratings for " + std::to_string(points.size()) + " questions");
    facts.kind->check_outcome(where, facts, outcome);
}

void check_status_change(const std::string& store, const std::string& session_uuid,
                         const std::string& current_status,
                         const std::string& new_status) {
    if (current_status == "completed" && new_status != "completed")
        throw StoreError(store + ": session " + session_uuid +
                         " is completed; refusing to set it " + new_status);
}

int participant_number_from_code(const std::string& code) {
    size_t end = code.size(), begin = end;
    while (begin > 0 && std::isdigit(static_cast<unsigned char>(code[begin - 1])))
        --begin;
    if (begin == end || end - begin > 9) return -1;
    return std::stoi(code.substr(begin));
}

std::pair<int, std::string> online_cell(const std::vector<int64_t>& counts, int number,
                                        const std::string& active_since_utc) {
    const int cells = static_cast<int>(counts.size());
    const int first = ((number % cells) + cells) % cells;
    int best = first;
    for (int k = 0; k < cells; ++k) {
        const int c = (first + k) % cells;
        if (counts[c] < counts[best]) best = c;
    }
    std::string per_cell;
    for (int64_t n : counts)
        per_cell += (per_cell.empty() ? "" : ",") + std::to_string(n);
    return {best, "online arrival " + std::to_string(number) + ": cell " +
                      std::to_string(best) + " of " + std::to_string(cells) +
                      ", the fewest completed + active sessions (per cell " + per_cell +
                      "; active = activity since " + active_since_utc + ")"};
}

SessionRow new_session_row(const std::string& uuid, int64_t participant_id, uint64_t seed,
                           const TrialPlan& plan) {
    SessionRow row;
    row.uuid = uuid;
    row.participant_id = participant_id;
    row.seed = seed;
    row.cell = plan.cell;
    row.status = "running";
    return row;
}

std::string block_order_text(const TrialPlan& plan) {
    std::string out;
    for (const std::string& b : plan.block_order) {
        if (!out.empty()) out += ',';
        out += b;
    }
    return out;
}

// One word for a segment's pictures: the common source, "mixed", or NULL when unknown.
std::optional<std::string> segment_source(
    const std::vector<StimulusProvenance>& stimuli) {
    std::set<std::string> sources;
    for (const StimulusProvenance& p : stimuli) sources.insert(p.source);
    if (sources.empty()) return std::nullopt;
    return sources.size() == 1 ? *sources.begin() : std::string("mixed");
}

std::optional<std::string> series_set_hash(
    const std::vector<StimulusProvenance>& pictures) {
    if (pictures.empty()) return std::nullopt;
    std::vector<std::pair<std::string, std::string>> held;
    for (const StimulusProvenance& p : pictures)
        held.emplace_back(p.stimulus, p.content_hash + "\t" + p.file + "\t" +
                                          p.software_version + "\t" + p.build_hash);
    std::sort(held.begin(), held.end());
    std::string text;
    for (const auto& [picture, what] : held) text += picture + "\t" + what + "\n";
    return sha256_hex(text);
}

ResolvedStimulus resolved_of(const StimulusProvenance& p) {
    ResolvedStimulus r{p.technique, p.mesh, p.mesh_hash, {}};
    for (const auto& [name, value] : p.values) r.values[name] = value;
    return r;
}

std::string resolved_difference(const std::string& stimulus, const ResolvedStimulus& a,
                                const std::string& a_name, const ResolvedStimulus& b,
                                const std::string& b_name) {
    auto differs = [&](const std::string& name, const std::string& x,
                       const std::string& y) {
        return "stimulus '" + stimulus + "': parameter '" + name + "' is " +
               (x.empty() ? "(none)" : x) + " in " + a_name + " but " +
               (y.empty() ? "(none)" : y) + " in " + b_name;
    };
    if (a.technique != b.technique) return differs("technique", a.technique, b.technique);
    if (a.mesh != b.mesh) return differs("mesh", a.mesh, b.mesh);
    if (a.mesh_hash != b.mesh_hash) return differs("mesh_hash", a.mesh_hash, b.mesh_hash);
    std::set<std::string> names;
    for (const auto& [name, value] : a.values) names.insert(name);
    for (const auto& [name, value] : b.values) names.insert(name);
    for (const std::string& name : names) {
        const auto x = a.values.find(name), y = b.values.find(name);
        const std::string vx = x == a.values.end() ? "" : x->second;
        const std::string vy = y == b.values.end() ? "" : y->second;
        if (vx != vy) return differs(name, vx, vy);
    }
    return "";
}

std::string shown_text(const std::vector<std::string>& shown) {
    std::string out;
    for (const std::string& id : shown) out += (out.empty() ? "" : " ") + id;
    return out;
}

std::vector<std::string> shown_from_text(const std::string& text) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find(' ', start);
        if (end == std::string::npos) end = text.size();
        if (end > start) out.push_back(text.substr(start, end - start));
        start = end + 1;
    }
    return out;
}

std::optional<std::string> shown_column(const PlannedTrial& trial) {
    if (trial.shown.empty()) return std::nullopt;
    return shown_text(trial.shown);
}

std::optional<int> expected_rating_column(const PlannedTrial& trial) {
    if (!trial.is_catch && trial.task != Task::staircase) return std::nullopt;
    if (trial.task != Task::rating && trial.expected == 0) return std::nullopt;
    return trial.expected;
}

Task task_column(const std::optional<std::string>& text) {
    if (!text) return Task::rating;
    if (const std::optional<Task> task = parse_task(*text)) return *task;
    // Written by a build with a kind this one lacks: never read as another kind.
    throw StoreError("a trial's kind is '" + *text +
                     "', which this build does not know (" + task_names_text() + ")");
}

std::string kind_column(const PlannedTrial& trial) { return task_name(trial.task); }

std::optional<std::string> legacy_task_column(const PlannedTrial& trial) {
    // Schema 6's CHECK on trials.task knows these four; every other kind leaves it NULL
    // (trials.kind is the kind).
    for (Task known : {Task::rating, Task::pair, Task::triad, Task::quadruple})
        if (trial.task == known) return std::string(task_name(trial.task));
    return std::nullopt;
}

std::optional<std::string> staircase_column(const PlannedTrial& trial) {
    if (trial.staircase.empty()) return std::nullopt;
    return trial.staircase;
}

}  // namespace lucent::study
