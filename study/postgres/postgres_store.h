#pragma once
// The PostgreSQL backend of StudyStore: one study server for many lab stations.
//
// - Schema: the SQLite migrations translated to PostgreSQL's types (postgres_schema.cpp),
//   version in table lucent_schema; applied only by `lucent store init`
//   (init_postgres_schema), and a server whose schema is newer is refused.
// - Stations at once: participant numbers (and with them the counterbalancing cell,
//   the Latin-square row) are taken under a transaction-scoped advisory lock, so two
//   stations never take one; a participant code being run holds a session-scoped
//   advisory lock, so a second station starting it is refused.
// - Failures: each trial goes to the local journal first (trial_journal.h), then to the
//   server; when the server cannot be reached the session runs on and later trials
//   resend the journal (idempotent by trial UUID), as does `lucent store sync`. A store
//   opened without a journal (`lucent serve`) sends each trial straight to the server
//   and throws StoreUnavailable when it cannot.
// - Every statement is parameterised (exec_params); the URI may not hold a password
//   (libpq reads PGPASSWORD or ~/.pgpass).
#include <map>
#include <memory>
#include <set>
#include <string>

#include "study/postgres/trial_journal.h"
#include "study/question_scales.h"
#include "study/study_store.h"

namespace lucent::study {

// Throws StoreError when the URI holds a password; returns it with connect_timeout set.
std::string checked_server_uri(const std::string& uri);
// Creates or migrates the server's schema; returns (version before, after).
std::pair<int, int> init_postgres_schema(const std::string& uri);
// The migration steps in PostgreSQL's dialect (same numbering as schema_migrations()).
std::vector<std::string> postgres_migrations();

class PostgresStore : public StudyStore {
public:
    PostgresStore(const std::string& uri, const StoreOptions& options);
    ~PostgresStore() override;

    const std::string& name() const override { return name_; }
    int64_t ensure_study(const Protocol& protocol) override;
    int64_t ensure_participant(int64_t study_id, const std::string& code,
                               int* number) override;
    void claim_participant(const std::string& code) override;
    // pg_advisory_unlock on this connection (a lost connection released it already).
    void release_participant(const std::string& code) override;
    OnlineSession enrol_online(int64_t study_id, const std::string& code,
                               const OnlineEnrolment& how,
                               const SessionEnvironment& env) override;
    void check_stimulus_values(const std::vector<StimulusProvenance>& stimuli) override;
    SessionRow create_session(int64_t study_id, int64_t participant_id,
                              const TrialPlan& plan, uint64_t seed,
                              const SessionEnvironment& env) override;
    std::optional<SessionRow> unfinished_session(const std::string& code) override;
    bool has_completed_session(const std::string& code) override;
    std::optional<SessionRow> session_by_uuid(const std::string& uuid) override;
    bool session_withdrawn(const std::string& uuid) override;
    std::vector<TrialRow> trials(int64_t session_id) override;
    int begin_segment(int64_t session_id, const SessionEnvironment& env) override;
    int resume_segment(int64_t session_id, const SessionEnvironment& env) override;
    void update_environment(int64_t session_id, const SessionEnvironment& env) override;
    void set_consent(int64_t session_id) override;
    bool decline_consent(int64_t study_id, const std::string& code,
                         const std::string& page_uuid) override;
    bool consent_declined(const std::string& page_uuid) override;
    bool forget_declined_session(int64_t session_id) override;
    bool has_consent(int64_t session_id) override;
    std::optional<std::string> web_position(int64_t session_id) override;
    void set_web_position(int64_t session_id, const std::string& position) override;
    // Journal first, then the server (see the file comment); the return value is the
    // server's when it answered, else whether every trial is now recorded here. Without
    // a journal: the server's transaction only, StoreUnavailable when it cannot be
    // reached (nothing is kept here, so nothing is acknowledged that it does not hold).
    bool record_trial(int64_t session_id, int64_t trial_id,
                      const TrialOutcome& outcome) override;
    bool complete_session_if_answered(int64_t session_id) override;
    // 'paused' while the server is unreachable is left as 'running' there (both resume).
    void set_status(int64_t session_id, const std::string& status, bool ended) override;
    bool withdraw_participant(const std::string& code) override;
    std::optional<ParticipantCounts> participant_counts(const std::string& code) override;
    int64_t query_int(const std::string& sql) override;
    void snapshot_to_sqlite(const std::string& sqlite_path) override;
    int pending_trials() override { return journal_ ? journal_->count() : 0; }
    int sync() override;
    int withdrawn_trials_dropped() const override { return withdrawn_dropped_; }

    // "" without a journal (StoreOptions::journal false).
    const std::string& journal_path() const;

private:
    // What the station knows of a session it runs, so trials are checked and journaled
    // while the server is away.
    struct SessionCache {
        std::string uuid;
        StudyQuestions questions;
        std::map<int64_t, std::string> trial_uuid;       // trial id -> uuid
        std::map<int64_t, std::string> trial_block;      // trial id -> block
        std::map<int64_t, Task> trial_kind;              // trial id -> trials.kind
        std::map<int64_t, std::string> trial_staircase;  // trial id -> its procedure
        std::set<int64_t> answered;  // on the server or journaled here
        std::set<int64_t> skipped;   // on the server, or by an answer journaled here
        // Every planned trial answered or skipped.
        bool complete() const;
    };
    enum class Sent { Stored, AlreadyThere, Withdrawn };

    struct Connection;         // the libpqxx connection, kept out of this header
    Connection& connection();  // (re)connects; throws StoreError when unreachable
    void drop_connection();
    template <class F>
    auto guarded(const char* what, F&& body);
    SessionCache& session_cache(int64_t session_id);
    // The open slots of the procedure `trial_id` finished (same block and staircase),
    // marked skipped in `cache`; returns those newly marked.
    static std::vector<int64_t> skip_finished(SessionCache& cache, int64_t trial_id);
    // One journaled trial to the server, in one transaction. `strict`: a trial already
    // holding ratings is refused (a fresh record); otherwise identical ratings confirm.
    // A trial of a session the server holds as withdrawn (withdrawn_sessions) is not
    // sent: Withdrawn, and the caller drops it from the journal.
    Sent send(const JournaledTrial& trial, bool strict, bool* completed);
    // Sends what the journal holds (oldest first); stops at the first unreachable server.
    int flush(const std::string& skip_uuid);

    std::string uri_;
    std::string name_;
    StoreOptions options_;
    std::unique_ptr<Connection> conn_;
    // Null when StoreOptions::journal is false: trials go straight to the server.
    std::unique_ptr<TrialJournal> journal_;
    std::set<std::string> claimed_;
    std::map<int64_t, SessionCache> sessions_;
    int withdrawn_dropped_ = 0;  // journaled trials dropped: their session was withdrawn
    int64_t next_attempt_ns_ =
        0;  // steady clock; no server attempt before it after a failure
};

}  // namespace lucent::study
