#pragma once
// A study database file before the store writes to it: the read-only safety check, and
// the schema's migrations applied to an open connection.
#include <string>

#include "study/schema.h"
#include "study/sqlite/database.h"

namespace lucent::study {

// Checks, without writing a byte, that `path` is a Lucent study database this build can
// use (or absent/empty). Throws StoreError with one line: not SQLite, corrupt, another
// application's database, or a newer schema.
void check_database_file(const std::string& path);

// Applies schema migrations 1..target to an open connection (tests build old versions).
void migrate(Database& db, int target = kSchemaVersion);

}  // namespace lucent::study
