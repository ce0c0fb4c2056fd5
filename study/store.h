#pragma once
// The study database (SQLite): studies, stimuli and their parameters, participants,
// sessions, the planned trials and one row per rating. WAL journal, synchronous=FULL,
// foreign keys on, schema version in user_version, application_id 'LUCN'.
//
// Durability contract: a session's full trial order is written before trial 1, and each
// trial's ratings are committed in one transaction (record_trial) before the next trial
// starts, so a crash loses at most the trial on screen and never duplicates a rating.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol.h"
#include "sqlite.h"
#include "trial_plan.h"

namespace lucent::study {

inline constexpr int32_t kApplicationId = 0x4C55434E;  // "LUCN"
inline constexpr int kSchemaVersion = 2;

// Checks, without writing a byte, that `path` is a Lucent study database this build can
// use (or absent/empty). Throws StoreError with one line: not SQLite, corrupt, another
// application's database, or a newer schema.
void check_database_file(const std::string& path);

// Applies schema migrations 1..target to an open connection (tests build old versions).
void migrate(Database& db, int target = kSchemaVersion);

// Machine-independent description of where a session ran.
struct SessionEnvironment {
    std::string machine_id;
    std::string software_version;
    std::string build_hash;
    std::string gl_vendor;
    std::string gl_renderer;
    std::string display_mode;                  // e.g. "1280x1024 fullscreen, mode 60 Hz"
    std::optional<double> display_refresh_hz;  // video mode's rate; NULL when it says 0
    std::optional<double> measured_refresh_hz; // from swap intervals; NULL when unknown
    std::string refresh_note;                  // why a refresh is NULL, or a warning
};

struct SessionRow {
    int64_t id = 0;
    std::string uuid;
    int64_t participant_id = 0;
    std::string participant;
    uint64_t seed = 0;
    int cell = 0;
    std::string status;  // running, paused, completed, aborted
};

struct TrialRow {
    int64_t id = 0;
    int position = 0;
    std::string block;
    std::string stimulus;
    bool practice = false;
    bool is_catch = false;
    std::string prompt;
    int expected = 0;
    bool break_before = false;
    bool answered = false;
};

// One rating as the runner collected it.
struct Response {
    std::string question;
    int rating = 0;          // 1..points
    double rt_ms = 0;        // from stimulus onset to the final choice
    int changes = 0;         // times the choice changed after the first one
    int64_t first_choice_ns = 0;  // steady-clock timestamps (raw, monotonic)
    int64_t final_choice_ns = 0;
};

struct TrialOutcome {
    int64_t onset_ns = 0;    // first swap showing the stimulus, after glFinish
    int64_t confirm_ns = 0;  // when the answer was made final
    std::optional<int> dropped_frames;  // NULL when the refresh is unknown
    std::vector<Response> responses;
};

class Store {
public:
    // Opens (creating when absent) after check_database_file; `vfs` is for fault tests.
    explicit Store(const std::string& path, const std::string& vfs = "");

    // The study row for this protocol, created with its stimuli on first use. A database
    // holds one protocol: a different hash is refused with a one-line error.
    int64_t ensure_study(const Protocol& protocol);
    // Participant by code, created when new. Number: the code's trailing digits, else
    // one past the highest number in this database (so never one a participant holds);
    // it selects the Latin-square row.
    int64_t ensure_participant(int64_t study_id, const std::string& code, int* number);

    // Writes the session and its full planned trial order in one transaction.
    SessionRow create_session(int64_t study_id, int64_t participant_id, const TrialPlan& plan,
                              uint64_t seed, const SessionEnvironment& env);
    // The participant's newest running or paused session (not completed, not declined).
    std::optional<SessionRow> unfinished_session(const std::string& participant_code);
    bool has_completed_session(const std::string& participant_code);
    std::vector<TrialRow> trials(int64_t session_id);
    void update_environment(int64_t session_id, const SessionEnvironment& env);
    void set_consent(int64_t session_id);
    bool has_consent(int64_t session_id);
    // Commits one trial's ratings atomically; refuses a trial that already has ratings.
    void record_trial(int64_t session_id, int64_t trial_id, const TrialOutcome& outcome);
    void set_status(int64_t session_id, const std::string& status, bool ended);

    // Deletes a participant and everything recorded for them; false when unknown.
    bool withdraw_participant(const std::string& code);

    Database& db() { return db_; }

private:
    Database db_;
};

std::string utc_now_iso8601();
std::string new_uuid_v4();
std::string machine_id();

}  // namespace lucent::study
