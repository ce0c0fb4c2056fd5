// A station's trials on the server: each one journaled on this machine first
// (trial_journal.h), then sent in one transaction; resends are idempotent by trial UUID,
// as is `lucent store sync`.
#include <map>
#include <pqxx/pqxx>
#include <set>

#include "study/postgres/server_connection.h"
#include "study/schema.h"
#include "study/store_rules.h"
#include "study/time_and_ids.h"

namespace lucent::study {

using namespace postgres_internal;

// ---- [4] trials: journal, send, sync -------------------------------------------------

namespace {

// Sets the session completed when every planned trial has ratings or was skipped,
// inside `tx`.
bool complete_if_answered(pqxx::work& tx, int64_t session_id) {
    tx.exec_params(
        "UPDATE sessions SET status = 'completed', ended_utc = coalesce(ended_utc, $1) "
        "WHERE id = $2 AND status <> 'completed' AND NOT EXISTS (SELECT 1 FROM trials t "
        "WHERE t.session_id = sessions.id AND " +
            open_trial_sql() + ")",
        utc_now_iso8601(), session_id);
    const pqxx::result r = tx.exec_params(
        "SELECT status = 'completed' FROM sessions WHERE id = $1", session_id);
    return !r.empty() && r[0][0].as<bool>();
}

}  // namespace

PostgresStore::Sent PostgresStore::send(const JournaledTrial& j, bool strict,
                                        bool* completed) {
    return guarded("sending a trial", [&] {
        pqxx::work tx(connection());
        // A withdrawn participant's trial is never sent back (withdrawal.h).
        if (!tx.exec_params("SELECT 1 FROM withdrawn_sessions WHERE uuid = $1",
                            j.session_uuid)
                 .empty())
            return Sent::Withdrawn;
        const pqxx::result t = tx.exec_params(
            "SELECT id, session_id, skipped, block, coalesce(staircase, ''), "
            "final_value, intensity, (SELECT count(*) FROM adjustments a WHERE "
            "a.trial_id = trials.id) FROM trials WHERE uuid = $1 FOR UPDATE",
            j.trial_uuid);
        if (t.empty())
            throw StoreError(name_ + ": trial " + j.trial_uuid + " (session " +
                             j.session_uuid +
                             ") is not on the server (participant withdrawn?)" +
                             (journal_ ? "; kept in " + journal_->path() : ""));
        const int64_t trial_id = t[0][0].as<int64_t>(),
                      session_id = t[0][1].as<int64_t>();
        const pqxx::result held = tx.exec_params(
            "SELECT question, rating FROM responses WHERE trial_id = $1 ORDER BY "
            "question",
            trial_id);
        if (!held.empty()) {
            if (strict) refuse_second_answer(name_, trial_id);
            // A resend of a commit whose reply was lost: the same answer confirms it.
            std::map<std::string, int> mine, theirs;
            for (const Response& r : j.outcome.responses) mine[r.question] = r.rating;
            for (const pqxx::row& r : held)
                theirs[r[0].as<std::string>()] = r[1].as<int>();
            if (mine != theirs || optional_double(t[0][5]) != j.outcome.final_value ||
                optional_double(t[0][6]) != j.outcome.intensity ||
                t[0][7].as<int64_t>() !=
                    static_cast<int64_t>(j.outcome.adjustments.size()))
                throw StoreError(name_ + ": trial " + j.trial_uuid +
                                 " holds another answer on the server than in " +
                                 journal_path() + "; kept in the journal");
            if (completed) *completed = complete_if_answered(tx, session_id);
            tx.commit();
            return Sent::AlreadyThere;
        }
        // Another answer finished this slot's procedure on the server meanwhile.
        if (t[0][2].as<int>() != 0) refuse_skipped_trial(name_, trial_id);
        for (const Response& r : j.outcome.responses)
            tx.exec_params("INSERT INTO responses (session_id, trial_id, " +
                               std::string(kResponseColumns) +
                               ") VALUES ($1, $2, $3, $4, $5, $6, $7, $8)",
                           session_id, trial_id, r.question, r.rating, r.rt_ms, r.changes,
                           r.first_choice_ns, r.final_choice_ns);
        tx.exec_params(
            "UPDATE trials SET onset_ns = $1, confirm_ns = $2, dropped_frames = $3, "
            "answered_utc = $4, segment_id = (SELECT max(id) FROM session_segments "
            "WHERE session_id = $5), final_value = $6, intensity = $7 WHERE id = $8",
            j.outcome.onset_ns, j.outcome.confirm_ns, j.outcome.dropped_frames,
            j.recorded_utc, session_id, j.outcome.final_value, j.outcome.intensity,
            trial_id);
        for (size_t k = 0; k < j.outcome.adjustments.size(); ++k) {
            const Adjustment& a = j.outcome.adjustments[k];
            tx.exec_params(
                "INSERT INTO adjustments (trial_id, step, value, t_ns, input) VALUES "
                "($1, $2, $3, $4, $5)",
                trial_id, static_cast<int64_t>(k + 1), a.value, a.t_ns, a.input);
        }
        // The procedure has finished: its slots still open in this block are skipped.
        if (j.outcome.finishes_staircase)
            tx.exec_params(
                "UPDATE trials SET skipped = 1 WHERE session_id = $1 AND block = $2 AND "
                "staircase = $3 AND id <> $4 AND " +
                    open_trial_sql("trials"),
                session_id, t[0][3].as<std::string>(), t[0][4].as<std::string>(),
                trial_id);
        const bool done = complete_if_answered(tx, session_id);
        tx.commit();
        if (completed) *completed = done;
        return Sent::Stored;
    });
}

bool PostgresStore::record_trial(int64_t session_id, int64_t trial_id,
                                 const TrialOutcome& outcome) {
    SessionCache& cache = session_cache(session_id);
    const auto uuid = cache.trial_uuid.find(trial_id);
    const bool part_of_session = uuid != cache.trial_uuid.end();
    check_trial_answer(
        name_, session_id, trial_id,
        {.part_of_session = part_of_session,
         .answered = part_of_session && (cache.answered.count(trial_id) ||
                                         (journal_ && journal_->contains(uuid->second))),
         .kind = part_of_session ? cache.trial_kind[trial_id] : Task::rating,
         .skipped = part_of_session && cache.skipped.count(trial_id) > 0,
         .staircase = part_of_session ? cache.trial_staircase[trial_id] : std::string()},
        part_of_session ? cache.questions.of_block(cache.trial_block[trial_id])
                        : cache.questions.rating,
        outcome);
    const std::string where = name_ + ": trial " + std::to_string(trial_id);
    if (uuid->second.empty())
        throw StoreError(where +
                         " has no UUID (planned before schema 4); cannot journal it");

    const JournaledTrial journaled{uuid->second, cache.uuid, utc_now_iso8601(), outcome};
    if (!journal_) {
        // `lucent serve`: acknowledged only once the server's transaction committed; an
        // unreachable server throws (Unreachable is a StoreUnavailable) and nothing is
        // kept here. A commit whose reply was lost is on the server: the page's retry
        // finds the trial answered there.
        bool completed = false;
        if (send(journaled, true, &completed) == Sent::Withdrawn)
            throw StoreError(where + ": session " + cache.uuid +
                             " was withdrawn on the server; the trial is not kept");
        cache.answered.insert(trial_id);
        if (outcome.finishes_staircase) skip_finished(cache, trial_id);
        return completed;
    }
    // Durable on this machine first; only then the network.
    journal_->add(journaled);
    cache.answered.insert(trial_id);
    const std::vector<int64_t> skipped_now = outcome.finishes_staircase
                                                 ? skip_finished(cache, trial_id)
                                                 : std::vector<int64_t>();
    // Undoes what this trial marked here, when the server refuses it.
    auto forget = [&] {
        journal_->remove(journaled.trial_uuid);
        cache.answered.erase(trial_id);
        for (int64_t id : skipped_now) cache.skipped.erase(id);
    };
    const bool local_completed = cache.complete();
    if (steady_ns() < next_attempt_ns_) return local_completed;
    // One sender at a time per journal (every station of this server on this machine
    // shares it), older trials first: each session's trials reach the server in the order
    // they were recorded, and no two stations send one trial at once.
    const TrialJournal::SendLock sending(*journal_);
    const int64_t attempt = next_attempt_ns_;
    flush(journaled.trial_uuid);
    if (next_attempt_ns_ != attempt)
        return local_completed;  // unreachable: all stay journaled
    // Another station sent it from the shared journal while this one waited: confirmed.
    if (!journal_->contains(journaled.trial_uuid)) return local_completed;
    bool completed = local_completed;
    try {
        if (send(journaled, true, &completed) == Sent::Withdrawn) {
            forget();
            throw StoreError(where + ": session " + cache.uuid +
                             " was withdrawn on the server; the trial is not kept");
        }
        journal_->remove(journaled.trial_uuid);
    } catch (const Unreachable&) {
        next_attempt_ns_ = steady_ns() + int64_t(options_.retry_interval_ms) * 1'000'000;
        return local_completed;
    } catch (const StoreError&) {
        // The server refused this trial (not a network failure): nothing of it is kept.
        forget();
        throw;
    }
    return completed;
}

int PostgresStore::flush(const std::string& skip_uuid) {
    int confirmed = 0;
    for (const JournaledTrial& j : journal_->pending()) {
        if (j.trial_uuid == skip_uuid) continue;
        try {
            const Sent sent = send(j, false, nullptr);
            journal_->remove(j.trial_uuid);
            if (sent == Sent::Withdrawn) {
                ++withdrawn_dropped_;
                continue;
            }
            ++confirmed;
        } catch (const Unreachable&) {
            next_attempt_ns_ =
                steady_ns() + int64_t(options_.retry_interval_ms) * 1'000'000;
            break;
        } catch (const StoreError&) {
            continue;  // refused (e.g. withdrawn): kept for `lucent store sync` to report
        }
    }
    return confirmed;
}

int PostgresStore::sync() {
    if (!journal_) return 0;
    const TrialJournal::SendLock sending(*journal_);
    int confirmed = 0;
    for (const JournaledTrial& j : journal_->pending()) {
        // Unreachable or refused: one line, the rest stays. A withdrawn session's trial
        // leaves the journal unsent.
        const Sent sent = send(j, false, nullptr);
        journal_->remove(j.trial_uuid);
        if (sent == Sent::Withdrawn)
            ++withdrawn_dropped_;
        else
            ++confirmed;
    }
    next_attempt_ns_ = 0;
    return confirmed;
}

bool PostgresStore::SessionCache::complete() const {
    for (const auto& [id, uuid] : trial_uuid)
        if (!answered.count(id) && !skipped.count(id)) return false;
    return true;
}

bool PostgresStore::complete_session_if_answered(int64_t session_id) {
    return guarded("completing the session", [&] {
        pqxx::work tx(connection());
        const bool done = complete_if_answered(tx, session_id);
        tx.commit();
        return done;
    });
}

}  // namespace lucent::study
