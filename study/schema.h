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
inline constexpr int kSchemaVersion = 5;

// Migration steps 1..kSchemaVersion; step i brings a store from version i-1 to i.
const std::vector<std::string>& schema_migrations();

// Online allocation (enrol_online): the SQL giving (cell, completed + active sessions) of
// study ?1/$1 with activity since ?2/$2, in SQLite's or PostgreSQL's dialect.
std::string online_cell_counts_sql(bool postgres);

}  // namespace lucent::study
