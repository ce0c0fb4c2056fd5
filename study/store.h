#pragma once
// The study database (SQLite): studies, stimuli and their parameters, participants,
// sessions, the planned trials and one row per rating. WAL journal, synchronous=FULL,
// foreign keys on, schema version in user_version, application_id 'LUCN'.
//
// Provenance (schema 3): every resolved knob value of each stimulus, its mesh and mesh
// hash (fixed per study: a later session or a merge that would show different values is
// refused), and per session segment (the start and each resume) the environment and
// where each picture came from (live, or a --images file checked against its manifest).
//
// Durability contract: a session's full trial order is written before trial 1, and each
// trial's ratings are committed in one transaction (record_trial) before the next trial
// starts, so a crash loses at most the trial on screen and never duplicates a rating.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "protocol.h"
#include "question_scales.h"
#include "sqlite.h"
#include "trial_plan.h"

namespace lucent::study {

inline constexpr int32_t kApplicationId = 0x4C55434E;  // "LUCN"
inline constexpr int kSchemaVersion = 3;

// Checks, without writing a byte, that `path` is a Lucent study database this build can
// use (or absent/empty). Throws StoreError with one line: not SQLite, corrupt, another
// application's database, or a newer schema.
void check_database_file(const std::string& path);

// Applies schema migrations 1..target to an open connection (tests build old versions).
void migrate(Database& db, int target = kSchemaVersion);

// What one stimulus is, as the renderer resolved it and as a segment shows it.
struct StimulusProvenance {
    std::string stimulus;   // protocol id
    std::string source;     // "live", "images" (a --images file checked against its
                            // manifest) or "image" (the protocol's own image file)
    std::string technique;  // "" for image stimuli
    std::string mesh;       // resolved mesh spec (the default when the protocol names none)
    std::string mesh_hash;  // content hash of that mesh
    // Every knob of the technique and the scene, defaults included, in knob order, as
    // format_knob_value() writes them; empty for image stimuli.
    std::vector<std::pair<std::string, std::string>> values;
    std::string software_version;  // the lucent that made the picture (the manifest's for
    std::string build_hash;        // --images files)
    std::string file;          // the image file shown; "" when rendered live
    std::string content_hash;  // the manifest's content hash of that file; "" when live
};

// Where a session segment ran.
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
    std::vector<StimulusProvenance> stimuli;   // what this segment shows (may be empty)
};

// The resolved description of a stimulus as stored (technique, mesh, mesh hash, every
// knob value); compared between sessions and between databases being merged.
struct ResolvedStimulus {
    std::string technique;
    std::string mesh;
    std::string mesh_hash;
    std::map<std::string, std::string> values;
};
// Stimulus key -> its resolved description, for stimuli that have one (schema 3 and a
// session that recorded it); older databases give an empty map.
std::map<std::string, ResolvedStimulus> read_resolved_stimuli(Database& db);
// "" when equal, else "stimulus 'ID': parameter 'NAME' is A in <a_name> but B in
// <b_name>" for the first difference (technique, mesh, mesh_hash or a knob value).
std::string resolved_difference(const std::string& stimulus, const ResolvedStimulus& a,
                                const std::string& a_name, const ResolvedStimulus& b,
                                const std::string& b_name);

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

    // Throws StoreError naming the stimulus and parameter when `stimuli` resolve to other
    // values than this database's earlier sessions recorded (new values are not stored).
    void check_stimulus_values(const std::vector<StimulusProvenance>& stimuli);
    // Writes the session, its first segment (env, env.stimuli) and its full planned trial
    // order in one transaction.
    SessionRow create_session(int64_t study_id, int64_t participant_id, const TrialPlan& plan,
                              uint64_t seed, const SessionEnvironment& env);
    // The participant's newest running or paused session (not completed, not declined).
    std::optional<SessionRow> unfinished_session(const std::string& participant_code);
    bool has_completed_session(const std::string& participant_code);
    std::vector<TrialRow> trials(int64_t session_id);
    // A resume: adds segment n+1 with `env` and what it shows (earlier segments keep
    // their machine, GL, display and refresh details). Returns the segment number.
    int begin_segment(int64_t session_id, const SessionEnvironment& env);
    // Updates the newest segment's environment (e.g. the measured refresh); the session
    // row's copy (the first segment's) only while the session has one segment.
    void update_environment(int64_t session_id, const SessionEnvironment& env);
    void set_consent(int64_t session_id);
    bool has_consent(int64_t session_id);
    // Commits one trial's ratings atomically; refuses a trial that already has ratings,
    // lacks a question, names one the study does not ask, or has a rating outside
    // 1..points of its question.
    // The trial that answers the session's last open trial also sets it `completed` (with
    // ended_utc) in the same transaction, so no crash can leave it answered but open.
    // Returns true when the session is now completed.
    bool record_trial(int64_t session_id, int64_t trial_id, const TrialOutcome& outcome);
    // Sets `completed` when every planned trial has its ratings (repairs sessions written
    // before completion was atomic); true when the session is completed afterwards.
    bool complete_session_if_answered(int64_t session_id);
    // A completed session is final: any other status for it throws StoreError.
    void set_status(int64_t session_id, const std::string& status, bool ended);

    // Deletes a participant and everything recorded for them; false when unknown.
    bool withdraw_participant(const std::string& code);

    Database& db() { return db_; }

private:
    // Stores (first time) or checks env.stimuli's resolved values, then the segment's rows.
    void insert_segment(int64_t session_id, int segment, const SessionEnvironment& env);

    const QuestionPoints& question_points_of_session(int64_t session_id);

    Database db_;
    std::map<int64_t, QuestionPoints> question_points_by_session_;  // parsed once
};

std::string utc_now_iso8601();
std::string new_uuid_v4();
std::string machine_id();

}  // namespace lucent::study
