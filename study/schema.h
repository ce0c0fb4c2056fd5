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
inline constexpr int kSchemaVersion = 6;

// Migration steps 1..kSchemaVersion; step i brings a store from version i-1 to i.
const std::vector<std::string>& schema_migrations();

// Online allocation (enrol_online): the SQL giving (cell, completed + active sessions) of
// study ?1/$1 with activity since ?2/$2, in SQLite's or PostgreSQL's dialect.
std::string online_cell_counts_sql(bool postgres);

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
