#pragma once
// A study database as the one table the statistics read (common/observation_table.h):
// every answered trial of every kind, one row per answer, with its stimulus's factors.
// The analysis (app/study_input.h) takes ratings, choices and matches out of one read of
// one snapshot; `lucent export` writes the same rows.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/observation_table.h"
#include "study/export.h"
#include "study/protocol.h"

namespace lucent::study {

struct ObservationOptions {
    // The analysis's view: practice trials left out, only the sessions `sessions` (or
    // the stored plan) names, and, with `exclude_failed_catch`, the participants who
    // failed more catch trials than the protocol allows. Otherwise every answer of every
    // session not withdrawn, practice included, flagged.
    bool analysis = true;
    bool exclude_failed_catch = true;
    std::string sessions;  // analysis: "completed" or "all"; empty: the stored plan's
};

struct StudyObservations {
    common::ObservationTable table;
    // The protocol the database was made with; empty when absent or unparseable.
    std::optional<Protocol> protocol;
    std::string sessions = "completed";  // the rule the sessions were taken by
    SessionSelection selection;          // which were taken and left out, and the note
    // Each forced-choice block's stimuli in the stored protocol's order (its series);
    // empty when the protocol cannot be read.
    std::map<std::string, std::vector<std::string>> choice_orders;
};

// Throws StoreError (one line) when the file is not a readable study database, the
// rule is not "completed" or "all", or a forced choice's series parameter is not a
// number. A database before schema 6 holds ratings only, before 7 no adjust or
// staircase trials.
StudyObservations read_observations(const std::string& db_path,
                                    const ObservationOptions& options = {});

}  // namespace lucent::study
