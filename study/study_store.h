#pragma once
// The study store as the runner, the tools and the tests see it: one interface, two
// backends chosen by the --db argument's name (as Polyscope picks a render backend):
//
//   FILE.db                          SQLite file on this machine (store.h)
//   postgresql://USER@HOST[:PORT]/DB a PostgreSQL server for many stations (postgres/)
//
// Both keep the same schema (the same migrations, same version numbers) and the same
// guarantees: the planned trial order written before trial 1, each trial's ratings
// committed in one transaction before the next trial starts, nothing recorded twice.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/store_types.h"
#include "study/trial_plan.h"

namespace lucent::study {

// How `lucent serve` enrols a participant who has just consented (enrol_online).
struct OnlineEnrolment {
    std::string
        session_uuid;  // chosen before consent: the page's token is derived from it
    uint64_t seed = 0;
    int cells =
        1;  // counterbalancing cells (Latin-square rows; 1 without counterbalancing)
    // A session that is neither completed nor active since this time (ISO 8601 UTC, as
    // stored) is abandoned: its cell counts as free again.
    std::string active_since_utc;
    std::function<TrialPlan(int cell)>
        plan;  // the plan of the cell chosen (plan.cell == cell)
    // The participant agreed on the consent screen: sessions.consent_utc is written in
    // the enrolment's own transaction, so no session is ever stored without the consent
    // it was enrolled on (false: a protocol without a consent screen).
    bool consented = false;
};

struct OnlineSession {
    SessionRow session;
    int number = 0;          // the participant's number (arrival order)
    std::string allocation;  // as stored in sessions.allocation
};

class StudyStore {
public:
    virtual ~StudyStore() = default;

    // What messages call this store: the file path, or the URI (never a password).
    virtual const std::string& name() const = 0;

    // The study row for this protocol, created with its stimuli on first use. A store
    // holds one protocol: a different hash is refused with a one-line error.
    virtual int64_t ensure_study(const Protocol& protocol) = 0;
    // Participant by code, created when new. Number: the code's trailing digits, else
    // one past the highest number held or retired (allocated atomically, so two stations
    // never hand out one number); it selects the Latin-square row (the cell).
    virtual int64_t ensure_participant(int64_t study_id, const std::string& code,
                                       int* number) = 0;
    // Marks `code` as being run by this process until the store is closed. Throws
    // StoreError (one line) when another station or process runs that participant now.
    virtual void claim_participant(const std::string& code) = 0;
    // Ends this process's claim on `code` (a session completed, declined or left idle),
    // so another station or process may run the participant; a no-op when not claimed.
    virtual void release_participant(const std::string& code) = 0;
    // Online (`lucent serve`), once the participant consents, in one transaction under
    // the lock that hands out participant numbers: the participant (created when new,
    // numbered in arrival order: one past the highest number held or retired, whatever
    // the code's digits), the cell with the fewest completed + active sessions of the
    // study (active: not completed, not aborted, activity since how.active_since_utc;
    // ties go to the first such cell from number mod cells), the session with how.plan
    // of that cell, its first segment and its trials, and sessions.allocation saying
    // how the cell was chosen, and its consent when how.consented. Writes nothing when it
    // throws.
    virtual OnlineSession enrol_online(int64_t study_id, const std::string& code,
                                       const OnlineEnrolment& how,
                                       const SessionEnvironment& env) = 0;

    // Throws StoreError naming the stimulus and parameter when `stimuli` resolve to other
    // values than the earlier sessions recorded (new values are not stored).
    virtual void check_stimulus_values(
        const std::vector<StimulusProvenance>& stimuli) = 0;
    // Writes the session, its first segment (env, env.stimuli) and its full planned trial
    // order (each trial with a new UUID) in one transaction.
    virtual SessionRow create_session(int64_t study_id, int64_t participant_id,
                                      const TrialPlan& plan, uint64_t seed,
                                      const SessionEnvironment& env) = 0;
    // The participant's newest running or paused session (not completed, not declined).
    virtual std::optional<SessionRow> unfinished_session(const std::string& code) = 0;
    virtual bool has_completed_session(const std::string& code) = 0;
    // The session with this UUID, whatever its status (`lucent serve`: the session a
    // page's token names); nullopt when none.
    virtual std::optional<SessionRow> session_by_uuid(const std::string& uuid) = 0;
    // True when a session of this UUID was withdrawn (its tombstone, withdrawal.h).
    virtual bool session_withdrawn(const std::string& uuid) = 0;
    virtual std::vector<TrialRow> trials(int64_t session_id) = 0;
    // A resume: adds segment n+1 with `env` and what it shows. Returns its number.
    virtual int begin_segment(int64_t session_id, const SessionEnvironment& env) = 0;
    // A page reload (`lucent serve`): when no trial has been answered in the newest
    // segment, that segment is replaced by one with `env` (same number, started now),
    // else begin_segment. So reloads add at most one segment per answered trial.
    virtual int resume_segment(int64_t session_id, const SessionEnvironment& env) = 0;
    // Updates the newest segment's environment (e.g. the measured refresh); the session
    // row's copy (the first segment's) only while the session has one segment.
    virtual void update_environment(int64_t session_id,
                                    const SessionEnvironment& env) = 0;
    virtual void set_consent(int64_t session_id) = 0;
    // Participant `code` declined consent (schema 9: declined_codes). Counted once per
    // code however often it declines (a reload, a second page, a script reusing it), the
    // code kept only as a salted SHA-256 (withdrawal.h: salted_code); `page_uuid`
    // (`lucent serve`: the session UUID the declining page would have had; "" for a lab
    // station) becomes that code's declined page, so the page stays declined. One
    // transaction, the codes compared under a lock, so two processes never count one code
    // twice. A study keeps at most kMaxDeclinedCodes codes: past them a new code adds
    // nothing. True when `code` is counted now for the first time.
    virtual bool decline_consent(int64_t study_id, const std::string& code,
                                 const std::string& page_uuid) = 0;
    // True when the page of this UUID declined: its code's newest declined page
    // (decline_consent), or a page a serve before schema 9 kept in declined_pages.
    virtual bool consent_declined(const std::string& page_uuid) = 0;
    // A lab station's declined consent: when the session has no consent and no answered
    // trial, deletes it (segments, planned trials), and its participant when they have no
    // other session, and counts the participant's code as decline_consent does, in one
    // transaction; true then. Otherwise (a resumed session that had consent or answers)
    // changes nothing and returns false.
    virtual bool forget_declined_session(int64_t session_id) = 0;
    virtual bool has_consent(int64_t session_id) = 0;
    // `lucent serve` (schema 8): where the session's page stands, as the server wrote it
    // (web_study.cpp's text), so that any serve process continues it; nullopt when never
    // written (a lab session, or an older serve's).
    virtual std::optional<std::string> web_position(int64_t session_id) = 0;
    virtual void set_web_position(int64_t session_id, const std::string& position) = 0;
    // Commits one trial's ratings atomically; refuses a trial that already has ratings,
    // was skipped, lacks a question, names one the study does not ask, has a rating
    // outside 1..points of its question, or carries what its kind does not (schema 7:
    // an adjust trial its final value and adjustments, a staircase trial its intensity;
    // store_rules.h: check_trial_answer). In the same transaction: an adjust trial's
    // final value and adjustments, a staircase trial's intensity and, when the answer
    // finishes its staircase, the session's open slots of that block and procedure
    // marked skipped; and the session set `completed` when no trial is left open
    // (answered or skipped). Returns true when the session is now completed.
    virtual bool record_trial(int64_t session_id, int64_t trial_id,
                              const TrialOutcome& outcome) = 0;
    // Sets `completed` when every planned trial has its ratings or was skipped; true
    // when completed.
    virtual bool complete_session_if_answered(int64_t session_id) = 0;
    // A completed session is final: any other status for it throws StoreError.
    virtual void set_status(int64_t session_id, const std::string& status,
                            bool ended) = 0;
    // Deletes a participant and everything recorded for them; false when unknown.
    virtual bool withdraw_participant(const std::string& code) = 0;
    // Sessions and ratings held for `code`; nullopt when no such participant.
    virtual std::optional<ParticipantCounts> participant_counts(
        const std::string& code) = 0;

    // One integer from a constant, read-only SQL query both backends accept (tests and
    // diagnostics; never user input).
    virtual int64_t query_int(const std::string& sql) = 0;
    // Writes a consistent copy of everything (one snapshot) as a new SQLite study file at
    // `sqlite_path`, so export, analyze and merge read a server as they read a file.
    virtual void snapshot_to_sqlite(const std::string& sqlite_path) = 0;
    // Trials recorded here but not yet confirmed by the server (0 for local files).
    virtual int pending_trials() { return 0; }
    // Sends what is pending; returns how many trials the server confirmed now.
    virtual int sync() { return 0; }
    // Journaled trials dropped unsent because the server holds their session as
    // withdrawn (a withdrawal's tombstone); they never count as confirmed.
    virtual int withdrawn_trials_dropped() const { return 0; }
};

struct StoreOptions {
    // PostgreSQL: the local SQLite journal keeping trials until the server confirms them;
    // "" = default_journal_path(uri).
    std::string journal_path;
    // PostgreSQL: after a failed send, the next attempt waits at least this long (a
    // trial is journaled meanwhile, so the session runs on).
    int retry_interval_ms = 1000;
    // PostgreSQL: false sends each trial straight to the server (no local journal):
    // record_trial returns only once the server's transaction committed, and throws
    // StoreUnavailable when it cannot be reached. `lucent serve` opens it so: a server
    // process acknowledges to a browser only what the study's database holds.
    bool journal = true;
    // SQLite: the VFS (fault tests).
    std::string vfs;
};

// True for postgresql:// and postgres:// URIs (libpq's names).
bool is_server_uri(const std::string& db);
// Opens a store by the name of `db`. SQLite files are created and migrated on open; a
// server must be initialised first (`lucent store init`). A scheme this build does not
// know is refused with one line listing the valid ones.
std::unique_ptr<StudyStore> open_study_store(const std::string& db,
                                             const StoreOptions& options = {});
// Creates or migrates the schema (SQLite or server); returns (version before, after).
std::pair<int, int> init_study_store(const std::string& db);
// A read-only SQLite file for `db`: the file itself, or a snapshot of the server in a
// temporary file removed when the returned object dies.
class ReadableStudyFile {
public:
    explicit ReadableStudyFile(const std::string& db);
    ~ReadableStudyFile();
    ReadableStudyFile(const ReadableStudyFile&) = delete;
    ReadableStudyFile& operator=(const ReadableStudyFile&) = delete;
    const std::string& path() const { return path_; }
    // `text` (a note about the file read) naming the store as given, never the
    // temporary snapshot: a reader of a report cannot open /tmp/lucent-snapshot-*.
    std::string as_given(std::string text) const;

private:
    std::string given_;
    std::string path_;
    std::string temporary_dir_;
};

}  // namespace lucent::study
