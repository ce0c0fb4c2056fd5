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
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/question_scales.h"
#include "study/sqlite/database.h"
#include "study/store_types.h"
#include "study/study_store.h"
#include "study/trial_plan.h"

namespace lucent::study {

inline constexpr int32_t kApplicationId = 0x4C55434E;  // "LUCN"
inline constexpr int kSchemaVersion = 5;

// Checks, without writing a byte, that `path` is a Lucent study database this build can
// use (or absent/empty). Throws StoreError with one line: not SQLite, corrupt, another
// application's database, or a newer schema.
void check_database_file(const std::string& path);

// Applies schema migrations 1..target to an open connection (tests build old versions).
void migrate(Database& db, int target = kSchemaVersion);

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

// The SQLite backend of StudyStore (study_store.h documents each operation).
class Store : public StudyStore {
public:
    // Opens (creating when absent) after check_database_file; `vfs` is for fault tests.
    explicit Store(const std::string& path, const std::string& vfs = "");
    ~Store() override;

    const std::string& name() const override { return db_.path(); }
    int64_t ensure_study(const Protocol& protocol) override;
    int64_t ensure_participant(int64_t study_id, const std::string& code,
                               int* number) override;
    // Within one machine: an open-file-description lock on `<db>-participants.lock`,
    // released when this store closes or the process dies.
    void claim_participant(const std::string& code) override;
    // Unlocks the code's byte (unless another code claimed here shares it).
    void release_participant(const std::string& code) override;
    OnlineSession enrol_online(int64_t study_id, const std::string& code,
                               const OnlineEnrolment& how,
                               const SessionEnvironment& env) override;
    void check_stimulus_values(const std::vector<StimulusProvenance>& stimuli) override;
    SessionRow create_session(int64_t study_id, int64_t participant_id,
                              const TrialPlan& plan, uint64_t seed,
                              const SessionEnvironment& env) override;
    std::optional<SessionRow> unfinished_session(
        const std::string& participant_code) override;
    bool has_completed_session(const std::string& participant_code) override;
    std::vector<TrialRow> trials(int64_t session_id) override;
    int begin_segment(int64_t session_id, const SessionEnvironment& env) override;
    int resume_segment(int64_t session_id, const SessionEnvironment& env) override;
    void update_environment(int64_t session_id, const SessionEnvironment& env) override;
    void set_consent(int64_t session_id) override;
    void count_declined_consent(int64_t study_id) override;
    bool forget_declined_session(int64_t session_id) override;
    bool has_consent(int64_t session_id) override;
    bool record_trial(int64_t session_id, int64_t trial_id,
                      const TrialOutcome& outcome) override;
    // Also repairs sessions written before completion was atomic.
    bool complete_session_if_answered(int64_t session_id) override;
    void set_status(int64_t session_id, const std::string& status, bool ended) override;
    bool withdraw_participant(const std::string& code) override;
    std::optional<ParticipantCounts> participant_counts(const std::string& code) override;
    int64_t query_int(const std::string& sql) override { return db_.scalar_int(sql); }
    void snapshot_to_sqlite(const std::string& sqlite_path) override;

    Database& db() { return db_; }

private:
    // Stores (first time) or checks env.stimuli's resolved values, then the segment's
    // rows.
    void insert_segment(int64_t session_id, int segment, const SessionEnvironment& env);
    void copy_environment_to_session_row(int64_t session_id,
                                         const SessionEnvironment& env);
    // The session row, its first segment and its trials, inside the caller's transaction.
    SessionRow insert_session(int64_t study_id, int64_t participant_id,
                              const TrialPlan& plan, uint64_t seed,
                              const SessionEnvironment& env, const std::string& uuid,
                              const std::string& allocation);

    const QuestionPoints& question_points_of_session(int64_t session_id);

    Database db_;
    std::map<int64_t, QuestionPoints> question_points_by_session_;  // parsed once
    int claim_fd_ = -1;  // the participant lock file, once something is claimed
    std::map<std::string, int64_t> claimed_;  // code -> its locked byte
};

// Migration steps 1..kSchemaVersion in SQLite's dialect (the server backend translates
// the same text, so both schemas stay one).
const std::vector<std::string>& schema_migrations();

// Shared by the backends: a code's trailing digits as its number (-1 when none or over
// 9 digits); a provenance row as stored; one word for a segment's picture source.
int participant_number_from_code(const std::string& code);
// Online allocation (enrol_online): the SQL giving (cell, completed + active sessions) of
// study ?1/$1 with activity since ?2/$2, in SQLite's or PostgreSQL's dialect; the cell
// with the fewest (ties: the first from number mod cells) and the allocation text.
std::string online_cell_counts_sql(bool postgres);
std::pair<int, std::string> online_cell(const std::vector<int64_t>& counts, int number,
                                        const std::string& active_since_utc);
ResolvedStimulus resolved_of(const StimulusProvenance& p);
std::optional<std::string> segment_source(const std::vector<StimulusProvenance>& stimuli);

// UTC as 2026-12-02T16:56:02.123Z (milliseconds), the form every stored time uses.
std::string utc_iso8601(std::chrono::system_clock::time_point t);
std::string utc_now_iso8601();
std::string new_uuid_v4();
std::string machine_id();

}  // namespace lucent::study
