// Picking a store backend by the --db argument's name (study_store.h).
#include "study/study_store.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "study/postgres/postgres_store.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

bool is_server_uri(const std::string& db) {
    return db.rfind("postgresql://", 0) == 0 || db.rfind("postgres://", 0) == 0;
}

namespace {

// A name with a scheme this build does not serve ("mysql://...") is a mistake, not a
// file to create.
void refuse_unknown_scheme(const std::string& db) {
    const size_t colon = db.find("://");
    if (colon == std::string::npos || is_server_uri(db)) return;
    throw StoreError(
        "--db " + db + ": unknown store '" + db.substr(0, colon) +
        "'; valid: a FILE.db (SQLite) or postgresql://USER@HOST[:PORT]/DBNAME");
}

}  // namespace

std::unique_ptr<StudyStore> open_study_store(const std::string& db,
                                             const StoreOptions& options) {
    refuse_unknown_scheme(db);
    if (is_server_uri(db)) return std::make_unique<PostgresStore>(db, options);
    return std::make_unique<Store>(db, options.vfs);
}

std::pair<int, int> init_study_store(const std::string& db) {
    refuse_unknown_scheme(db);
    if (is_server_uri(db)) return init_postgres_schema(db);
    check_database_file(db);
    int before = 0;
    if (std::filesystem::exists(db) && std::filesystem::file_size(db) > 0)
        before = static_cast<int>(
            Database(db, SQLITE_OPEN_READONLY).scalar_int("PRAGMA user_version"));
    Store store(db);  // migrates on open
    return {before, kSchemaVersion};
}

ReadableStudyFile::ReadableStudyFile(const std::string& db) : given_(db) {
    refuse_unknown_scheme(db);
    if (!is_server_uri(db)) {
        path_ = db;
        return;
    }
    std::string pattern =
        (std::filesystem::temp_directory_path() / "lucent-snapshot-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
        throw StoreError("cannot create a temporary folder for " + db);
    temporary_dir_ = pattern;
    path_ = temporary_dir_ + "/snapshot.db";
    try {
        StoreOptions options;
        options.journal_path =
            temporary_dir_ + "/unused-journal.db";  // reads journal nothing
        PostgresStore(db, options).snapshot_to_sqlite(path_);
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove_all(temporary_dir_, ec);
        throw;
    }
}

std::string ReadableStudyFile::as_given(std::string text) const {
    if (path_ == given_) return text;
    for (size_t at = text.find(path_); at != std::string::npos;
         at = text.find(path_, at + given_.size()))
        text.replace(at, path_.size(), given_);
    return text;
}

ReadableStudyFile::~ReadableStudyFile() {
    if (temporary_dir_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(temporary_dir_, ec);
}

}  // namespace lucent::study
