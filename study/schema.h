#pragma once
// The one schema every study store creates: its version, the SQLite file's application
// id, and the migration steps in SQLite's dialect (the server backend translates the same
// text, so both schemas stay one). Shared SQL that differs only by dialect lives here
// too.
#include <cstdint>
#include <string>
#include <vector>

namespace lucent::study {

inline constexpr int32_t kApplicationId = 0x4C55434E;  // "LUCN"
inline constexpr int kSchemaVersion = 10;
// Schema 10 drops trials.kind's CHECK of the six built-in names: a kind is a registry
// entry (study/trials/). The step edits the table's SQL in SQLite's sqlite_schema, so
// each backend runs it its own way (migrate() in sqlite/database_file.cpp,
// postgres_migrations).
inline constexpr int kKindsFromRegistryVersion = 10;

// Migration steps 1..kSchemaVersion; step i brings a store from version i-1 to i.
const std::vector<std::string>& schema_migrations();

// The kind of trial `alias` (rating, pair, triad, quadruple, adjust or staircase) as SQL
// for a database of schema `version`: trials.kind from schema 7 on (trials.task when it
// is NULL), trials.task from 6, 'rating' before. Every reader of a trial's kind uses it.
std::string trial_kind_sql(int version, const std::string& alias = "t");
// The schema-7 condition on trials `alias` of a trial still open: not answered, not
// skipped. A session is complete when none of its trials is open.
std::string open_trial_sql(const std::string& alias = "t");

// Online allocation (enrol_online): the SQL giving (cell, completed + active sessions) of
// study ?1/$1 with activity since ?2/$2, in SQLite's or PostgreSQL's dialect.
std::string online_cell_counts_sql(bool postgres);

// A response's answer columns, in Response's order: both stores and the station journal
// write (after session_id, trial_id or trial_uuid) and read them in this order.
inline constexpr const char* kResponseColumns =
    "question, rating, rt_ms, changes, first_choice_ns, final_choice_ns";

// A segment's environment columns (the session row repeats the first segment's), in
// SessionEnvironment's order: each backend binds their values in this order.
inline constexpr int kEnvironmentColumnCount = 9;
inline constexpr const char* kEnvironmentColumns =
    "machine_id, software_version, build_hash, gl_vendor, gl_renderer, display_mode, "
    "display_refresh_hz, measured_refresh_hz, refresh_note";
// Their parameters in a VALUES list, the first numbered `first`: "?, ?, ..." in SQLite's
// dialect, "$first, ..." in PostgreSQL's.
std::string environment_values(bool postgres, int first);
// "machine_id = ?, ..." (SQLite) or "machine_id = $1, ..." (PostgreSQL): the columns as
// an UPDATE sets them, from parameter 1.
std::string environment_assignments(bool postgres);

}  // namespace lucent::study
