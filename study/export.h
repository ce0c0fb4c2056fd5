#pragma once
// Data out of a study database: CSV exports (long: one row per rating; wide: one row per
// participant; observations: one row per answer of every kind, study/observations.h),
// and merging databases from several machines.
#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "common/observation_table.h"
#include "study/protocol.h"

namespace lucent::study {

enum class ExportFormat { Long, Wide };

// Writes CSV (RFC 4180 quoting, one value per cell, never JSON) to `out`. Opens the
// database read-only after check_database_file. Returns the number of data rows.
// Long rows carry every resolved parameter of the stimulus shown, its mesh hash, where
// the picture came from and the renderer; ratings recorded without that (a database
// written before schema 3) keep only the protocol's values, the rest empty, and one line
// saying so is appended to `notes` (the CSV itself stays plain for CSV readers).
int export_csv(const std::string& db_path, ExportFormat format, std::ostream& out,
               std::vector<std::string>* notes = nullptr);

struct ExportFileResult {
    int rows = 0;
    // analysis, choice-analysis, observations: failing too many catch trials
    std::vector<std::string> excluded_participants;
    // long, wide: values older databases did not record; analysis, choice-analysis,
    // observations: the sessions left out by reason (SessionSelection::note)
    std::vector<std::string> notes;
};

// Writes format "long", "wide", "analysis", "choices", "choice-analysis" (the choices
// as the scaling reads them: ChoiceExportOptions::analysis), "adjustments", "matches",
// "staircase" (export_adjustments, ...) or "observations" (every answer the analysis
// reads, of every kind, one column per factor: common::write_observation_csv) of
// `db_path` to the CSV file
// `out_path`: never the database itself (by inode: symlinks, hard links and relative
// paths included) nor any other database; an existing file only with `force`. Written to
// a temporary file in the same folder and renamed into place. Throws StoreError (one
// line).
ExportFileResult export_file(const std::string& db_path, const std::string& format,
                             const std::string& out_path, bool force);

// The sessions an analysis leaves out, by reason (each session counted once, in this
// order: withdrawn, incomplete, failed catch trials).
struct SessionsLeftOut {
    int withdrawn = 0;   // withdrawn_sessions tombstones (their ratings already deleted)
    int incomplete = 0;  // status running, paused or aborted (sessions = "completed")
    std::map<std::string, int> incomplete_by_status;  // "running" -> 1, ...
    int failed_catch = 0;  // sessions of participants excluded for failed catch trials
    int total() const { return withdrawn + incomplete + failed_catch; }
};

// The sessions an analysis reads (withdrawn never; "completed" or "all" by status),
// the participants excluded for failed catch trials (when `exclude_failed_catch`, over
// the stored protocol's max_failed_catch), and the note saying so. Every reader of a
// study database for the analysis takes these.
struct SessionSelection {
    std::map<std::int64_t, std::string> taken;  // session id -> participant code
    std::set<std::string> excluded;             // participant codes
    std::vector<std::string> excluded_participants;
    SessionsLeftOut left_out;
    int total = 0, analysed = 0;
    std::string note;
    // A session read and not excluded.
    bool keeps(std::int64_t session) const {
        const auto it = taken.find(session);
        return it != taken.end() && !excluded.count(it->second);
    }
};
class Database;
// The protocol the database was made with; empty when absent or no longer parseable
// (a database from an older build whose keys this one does not know).
std::optional<Protocol> stored_protocol(Database& db);
SessionSelection select_sessions(Database& db, const std::string& db_path,
                                 const std::string& sessions, bool exclude_failed_catch);
// Who declined consent, named for what was counted; the sessions note ends with it.
// Schema 9: "2 participant codes declined consent" (each code once however often it
// declined; "at least 1000 ..." once kMaxDeclinedCodes are kept, past which a decline
// adds nothing). A database counting before schema 9 counted pages: "3 consent declines
// counted per page before schema 9 (page loads, not people)". "" when neither was kept
// (before schema 5).
std::string declined_consent_figure(Database& db);

// `lucent export --format analysis`: the ratings the one-way tests and mixed models read,
// one row per (rating, factor) (common::factor_ratings), as
// participant,stimulus,factor,level,question,rating. Returns the data rows.
int write_factor_ratings_csv(const common::ObservationTable& table, std::ostream& out);

// Forced choices (issue 30): one row per answered pair, triad or quadruple trial, as
// `lucent export --format choices` writes them and the scaling reads them
// (analysis/data/choice_table.h): participant,session,trial,block,task,question,
// practice,catch,expected,shown_1..shown_4 (the stimuli in screen order),value_1..
// value_4 (each one's value of the block's series parameter),choice (1 or 2, as
// PlannedTrial::shown says),rt_ms.
struct ChoiceExportOptions {
    // The analysis's view: practice trials left out, only the sessions `sessions` (or
    // the stored plan) names, participants failing more catch trials than the protocol
    // allows left out. Otherwise every answered choice, with its practice and catch
    // flags.
    bool analysis = false;
    std::string sessions;  // analysis: "completed" or "all"; empty: the stored plan's
};
struct ChoiceExport {
    int rows = 0;
    std::vector<std::string> excluded_participants;  // analysis only
    std::vector<std::string> notes;  // analysis: the sessions left out, by reason
};
ChoiceExport export_choices(const std::string& db_path, std::ostream& out,
                            const ChoiceExportOptions& options = {});

// Adjustment and staircase trials (issue 31), every session not withdrawn, practice
// included; numbers as their shortest exact text. Each returns its data rows (none from
// a database before schema 7).
//
// `lucent export --format adjustments`: one row per change of an adjust trial's knob,
// participant,session,trial,block,target,start_value,step,value,t_ms,input (t_ms from
// the trial's onset; step 1, 2, ... in the order made).
int export_adjustments(const std::string& db_path, std::ostream& out);
// `--format matches`: one row per answered adjust trial, participant,session,trial,
// block,practice,target,match_knob (the block's knob in the stored protocol; empty when
// it no longer parses),start_value,final_value,adjustments (their count),total_ms (the
// confirmation's RT).
int export_matches(const std::string& db_path, std::ostream& out);
// `--format staircase`: one row per answered staircase trial in position order,
// participant,session,trial,block,standard,staircase (its procedure),intensity (the
// delta shown),expected (the comparison's place),choice,correct (1 when choice is
// expected),rt_ms; skipped slots are not rows.
int export_staircase(const std::string& db_path, std::ostream& out);

struct MergeReport {
    int sessions_added = 0;
    // Copies of a session beyond the one kept that hold nothing more (identical).
    int sessions_already_present = 0;
    // Sessions of which one input held a copy that another extends (more answers, or
    // the same answers and a later status): the extending copy was kept.
    int sessions_extended = 0;
    // Sessions not merged because a withdrawal in some input covers them (withdrawal.h).
    int sessions_withdrawn = 0;
    // One line each: a code from several machines kept apart as several participants
    // ("P01: sessions from 2 machines are different people, kept apart as P01@3f2a9c1e
    // P01@77b0d2aa"), people of one code on one machine kept apart, an older input read
    // through an upgraded copy.
    std::vector<std::string> notes;
};

// Combines databases into `out_path`, a new file (never an input or any database),
// written under a temporary name and renamed when complete. `names` (one per input, or
// none) name the inputs in messages, e.g. a server's URI for its snapshot file.
//
// Sessions are matched by UUID. Copies of one session in several inputs are reconciled
// (merge_reconcile.h): the copy that extends every other (its answers a superset with
// equal ratings) is kept with its status, trials, ratings and segments, whatever the
// order of the inputs; copies that disagree on a rating, or each hold answers the other
// lacks, or name other participants or plans, are refused in one line naming the
// session, participant and trial. Withdrawals recorded in any input (withdrawal.h) drop
// the sessions they cover from every input, and the output keeps every tombstone.
//
// A participant is a code on one machine (sessions.machine_id): a code whose sessions
// come from several machines becomes one participant per machine, coded CODE@MACHINE
// (the shortest machine-id prefix of at least 8 characters that tells them apart). On
// one machine, sessions of one code from different inputs that one file could not have
// held together (two completed sessions: a station runs a code to completion once) are
// one person per group of inputs sharing sessions, coded CODE@MACHINE#1, #2, ... in the
// order of their first session's start. So two people are never fused. Inputs of an
// older schema are read through a migrated temporary copy; inputs holding different
// protocols (hashes), newer schemas or foreign files are refused before anything is
// written. Inputs are opened read-only and never modified.
MergeReport merge_databases(const std::vector<std::string>& inputs,
                            const std::string& out_path,
                            const std::vector<std::string>& names = {});

}  // namespace lucent::study
