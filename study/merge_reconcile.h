#pragma once
// Two copies of one session in a merge (a station file copied mid-session and again at
// the end, a backup and the file it came from): the copy that extends every other wins,
// each rating kept once; copies that disagree on a rating, or that each hold answers the
// other lacks, are refused in one line naming the session and the trial.
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "study/sqlite/database.h"

namespace lucent::study {

// One input's copy of a session, as far as reconciling needs it.
struct SessionCopy {
    int input = 0;  // index into the merge's inputs
    std::string code, machine_id, started_utc, status, seed, block_order;
    int64_t cell = 0;
    int segments = 0;
    struct Planned {
        std::string uuid, stimulus, block;  // uuid "" before schema 4
        int64_t practice = 0, is_catch = 0;
        bool operator==(const Planned&) const = default;
    };
    std::map<int64_t, Planned> plan;  // by position
    std::map<int64_t, std::map<std::string, int64_t>>
        answers;  // position -> question -> rating
    // Schema 7: what an answered adjust or staircase trial holds besides its rating, and
    // the staircase slots skipped; by position, for those trials only.
    struct Adjusted {
        double value = 0;
        int64_t t_ns = 0;
        std::string input;
        bool operator==(const Adjusted&) const = default;
    };
    struct Outcome {
        std::optional<double> final_value, intensity;
        std::vector<Adjusted> adjustments;
        bool skipped = false;
    };
    std::map<int64_t, Outcome> outcomes;
};

// Every session of `db` (uuid -> copy, without plan and answers), read-only.
std::map<std::string, SessionCopy> read_session_copies(Database& db, int input);
// Fills plan and answers of the copies `db` holds of the sessions in `wanted`.
void read_session_details(Database& db, std::map<std::string, SessionCopy*>& wanted);

// What reconciling the copies of one session decided.
struct Reconciled {
    size_t kept = 0;    // index of the copy that extends every other
    int identical = 0;  // other copies equal to it (already present)
    int extended = 0;   // other copies it extends (fewer answers, earlier status)
};

// Chooses the copy that extends every other (`names[input]` names inputs in messages).
// A trial is held by a copy that answered it or skipped it (a staircase slot). Throws
// StoreError, one line, when copies hold another participant or plan, disagree on a
// trial both hold (a rating, an adjust trial's final value or adjustments, a staircase
// trial's intensity, one answered where the other skipped), or no copy extends every
// other. The same copies in any order give the same
// copy (or the same refusal).
Reconciled reconcile_copies(const std::string& uuid,
                            const std::vector<SessionCopy>& copies,
                            const std::vector<std::string>& names);

}  // namespace lucent::study
