// A study file's safety check before anything writes to it, and its migrations.
#include "study/sqlite/database_file.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "study/schema.h"

namespace lucent::study {
namespace {

std::string hex32(uint32_t v) {
    char out[16];
    std::snprintf(out, sizeof out, "0x%08x", v);
    return out;
}

}  // namespace

void check_database_file(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(path, ec)) return;  // created on open
    if (fs::is_directory(path, ec))
        throw StoreError(path + ": is a directory, not a database");
    const auto size = fs::file_size(path, ec);
    const bool has_wal = fs::exists(path + "-wal", ec);
    if (size > 0) {
        char magic[16] = {};
        std::ifstream in(path, std::ios::binary);
        in.read(magic, sizeof magic);
        if (in.gcount() < 16 ||
            std::string(magic, 16) != std::string("SQLite format 3\0", 16))
            throw StoreError(path +
                             ": not a Lucent study database (not an SQLite file); "
                             "left unchanged");
    } else if (!has_wal) {
        return;  // an empty file: initialised on open
    }
    // Without a -wal file the main file is the whole database: open it immutable, so
    // not even the -wal/-shm side files of a WAL-mode database get created.
    const std::string uri = file_uri(path, has_wal ? "mode=ro" : "mode=ro&immutable=1");
    sqlite3* raw = nullptr;
    int rc = sqlite3_open_v2(uri.c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI,
                             nullptr);
    struct Closer {
        sqlite3* db;
        ~Closer() { sqlite3_close_v2(db); }
    } closer{raw};
    if (rc != SQLITE_OK)
        throw StoreError(path + ": cannot open read-only: " + sqlite3_errstr(rc));
    // Other stations' writers may hold the lock a moment: wait as the store itself does,
    // and never call a busy database corrupt.
    sqlite3_busy_timeout(raw, 5000);
    bool busy = false;
    auto query_int = [&](const char* sql, int64_t& out) -> std::string {
        sqlite3_stmt* stmt = nullptr;
        int r = sqlite3_prepare_v2(raw, sql, -1, &stmt, nullptr);
        if (r == SQLITE_OK) {
            r = sqlite3_step(stmt);
            if (r == SQLITE_ROW) {
                out = sqlite3_column_int64(stmt, 0);
                r = SQLITE_OK;
            }
        }
        std::string why = r == SQLITE_OK ? "" : sqlite3_errmsg(raw);
        busy = busy || (r & 0xFF) == SQLITE_BUSY || (r & 0xFF) == SQLITE_LOCKED;
        sqlite3_finalize(stmt);
        return why;
    };
    int64_t app_id = 0, version = 0, tables = 0;
    std::string why = query_int("PRAGMA application_id", app_id);
    if (why.empty()) why = query_int("PRAGMA user_version", version);
    if (why.empty()) why = query_int("SELECT count(*) FROM sqlite_schema", tables);
    if (!why.empty() && busy)
        throw StoreError(path + ": database is locked by another process for over 5 s (" +
                         why + "); try again");
    if (!why.empty())
        throw StoreError(path + ": database is corrupt (" + why + "); left unchanged");
    if (app_id == 0 && version == 0 && tables == 0) return;  // an empty SQLite file
    if (app_id != kApplicationId)
        throw StoreError(path + ": not a Lucent study database (application_id " +
                         hex32(static_cast<uint32_t>(app_id)) + ", " +
                         std::to_string(tables) + " schema entries); left unchanged");
    if (version > kSchemaVersion)
        throw StoreError(path + ": written by a newer Lucent (schema " +
                         std::to_string(version) + ", this build knows " +
                         std::to_string(kSchemaVersion) + "); left unchanged");
    sqlite3_stmt* stmt = nullptr;
    std::string check = "ok";
    if (sqlite3_prepare_v2(raw, "PRAGMA quick_check(1)", -1, &stmt, nullptr) !=
            SQLITE_OK ||
        sqlite3_step(stmt) != SQLITE_ROW) {
        check = sqlite3_errmsg(raw);
    } else {
        check = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
    }
    for (char& c : check)
        if (c == '\n' || c == '\r') c = ' ';  // errors stay on one line
    sqlite3_finalize(stmt);
    if (check != "ok")
        throw StoreError(path + ": database is corrupt (quick_check: " + check +
                         "); left unchanged");
}

void migrate(Database& db, int target) {
    const int current = static_cast<int>(db.scalar_int("PRAGMA user_version"));
    if (current >= target) return;
    Transaction tx(db);
    if (current == 0)
        db.exec("PRAGMA application_id = " + std::to_string(kApplicationId));
    for (int v = current + 1; v <= target; ++v) {
        db.exec(schema_migrations()[v - 1]);
        if (v == kKindsFromRegistryVersion) {
            // The step edited sqlite_schema: a new schema cookie makes every connection
            // (this one too) read the table's SQL again.
            db.exec("PRAGMA schema_version = " +
                    std::to_string(db.scalar_int("PRAGMA schema_version") + 1));
            Statement trials =
                db.prepare("SELECT sql FROM sqlite_schema WHERE name = 'trials'");
            if (trials.step() &&
                trials.text(0).find("CHECK (kind IN") != std::string::npos)
                throw StoreError(
                    db.path() +
                    ": schema 10 could not drop trials.kind's CHECK (the "
                    "table's SQL is not as schema 7 wrote it); left unchanged");
        }
    }
    db.exec("PRAGMA user_version = " + std::to_string(target));
    tx.commit();
}

}  // namespace lucent::study
