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
#include "study/schema.h"
#include "study/sqlite/database.h"
#include "study/sqlite/database_file.h"
#include "study/store_rules.h"
#include "study/store_types.h"
#include "study/study_store.h"
#include "study/time_and_ids.h"
#include "study/trial_plan.h"

namespace lucent::study {

// Stimulus key -> its resolved description, for stimuli that have one (schema 3 and a
// session that recorded it); older databases give an empty map.
std::map<std::string, ResolvedStimulus> read_resolved_stimuli(Database& db);

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

    const StudyQuestions& questions_of_session(int64_t session_id);
    // decline_consent inside the caller's transaction (a write lock: one decline at a
    // time compares the codes).
    bool add_declined_code(int64_t study_id, const std::string& code,
                           const std::string& page_uuid);

    Database db_;
    std::map<int64_t, StudyQuestions> questions_by_session_;  // parsed once
    int claim_fd_ = -1;  // the participant lock file, once something is claimed
    std::map<std::string, int64_t> claimed_;  // code -> its locked byte
};

}  // namespace lucent::study
