#pragma once
// Minimal RAII over the SQLite C API: one owner per connection and per statement, and
// errors as StoreError naming the database file.
#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "study/store_types.h"  // StoreError

namespace lucent::study {

class Statement;

// "file:" URI for sqlite3_open_v2/ATTACH with SQLITE_OPEN_URI; `query` e.g. "mode=ro".
std::string file_uri(const std::string& path, const std::string& query);

class Database {
public:
    // flags: SQLITE_OPEN_READONLY or SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE.
    Database(const std::string& path, int flags, const std::string& vfs = "");
    ~Database();
    Database(Database&& other) noexcept;
    Database& operator=(Database&&) = delete;
    Database(const Database&) = delete;

    void exec(std::string_view sql);
    Statement prepare(std::string_view sql);
    int64_t last_insert_id() const { return sqlite3_last_insert_rowid(db_); }
    int64_t scalar_int(std::string_view sql);
    [[noreturn]] void fail(const std::string& what) const;
    const std::string& path() const { return path_; }
    sqlite3* handle() const { return db_; }

private:
    sqlite3* db_ = nullptr;
    std::string path_;
};

class Statement {
public:
    Statement(const Database& db, sqlite3_stmt* stmt) : db_(&db), stmt_(stmt) {}
    ~Statement() { sqlite3_finalize(stmt_); }
    Statement(Statement&& o) noexcept : db_(o.db_), stmt_(o.stmt_) { o.stmt_ = nullptr; }
    Statement(const Statement&) = delete;

    Statement& bind(int index, int64_t value);
    Statement& bind(int index, int value) {
        return bind(index, static_cast<int64_t>(value));
    }
    Statement& bind(int index, double value);
    Statement& bind(int index, std::string_view value);
    Statement& bind(int index, const char* value) {
        return bind(index, std::string_view(value));
    }
    Statement& bind(int index, const std::string& value) {
        return bind(index, std::string_view(value));
    }
    Statement& bind_null(int index);
    template <class T>
    Statement& bind(int index, const std::optional<T>& value) {
        return value ? bind(index, *value) : bind_null(index);
    }
    // Steps once: true while a row is available.
    bool step();
    void run() {
        while (step()) {
        }
    }
    void reset() {
        sqlite3_reset(stmt_);
        sqlite3_clear_bindings(stmt_);
    }

    bool is_null(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
    int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
    double real(int col) const { return sqlite3_column_double(stmt_, col); }
    std::string text(int col) const;
    std::optional<double> optional_real(int col) const {
        return is_null(col) ? std::nullopt : std::optional<double>(real(col));
    }
    int columns() const { return sqlite3_column_count(stmt_); }
    std::string column_name(int col) const { return sqlite3_column_name(stmt_, col); }

private:
    const Database* db_;
    sqlite3_stmt* stmt_;
};

// BEGIN IMMEDIATE ... COMMIT; rolls back when destroyed without commit().
class Transaction {
public:
    explicit Transaction(Database& db);
    ~Transaction();
    void commit();

private:
    Database& db_;
    bool done_ = false;
};

}  // namespace lucent::study
