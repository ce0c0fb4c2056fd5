#pragma once
// Shared by the PostgreSQL backend's files (postgres_store.cpp, postgres_schema.cpp,
// postgres_trials.cpp), not by its users: the connection, the advisory lock keys, and
// guarded(), which turns libpqxx's exceptions into StoreError, or Unreachable when the
// server went away and the caller may journal and retry.
#include <chrono>
#include <cstdint>
#include <optional>
#include <pqxx/pqxx>
#include <string>

#include "study/postgres/postgres_store.h"

namespace lucent::study {
namespace postgres_internal {

// Advisory lock keys (two-key form, class 0x4C55 'LU'): the study rows, participant
// numbers, and declined codes (compared one decline at a time, so a code is counted
// once). Participant claims use the one-key form over a hash of the code.
constexpr int kLockClass = 0x4C55;
constexpr int kStudyLock = 1;
constexpr int kNumberLock = 2;
constexpr int kDeclineLock = 3;

// The server could not be reached, or went away mid-transaction: the caller may journal
// and retry. Anything else is a real refusal.
class Unreachable : public StoreUnavailable {
public:
    using StoreUnavailable::StoreUnavailable;
};

inline std::string first_line(const std::string& s) {
    std::string out = s.substr(0, s.find('\n'));
    while (!out.empty() && (out.back() == ' ' || out.back() == '\r')) out.pop_back();
    return out;
}

// SQLSTATE classes 08 (connection exception) and 57 (operator intervention: shutdown).
inline bool is_connection_state(const std::string& state) {
    return state.rfind("08", 0) == 0 || state.rfind("57", 0) == 0;
}

inline int64_t steady_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// A nullable DOUBLE PRECISION (libpqxx 6 reads no std::optional<double>).
inline std::optional<double> optional_double(const pqxx::field& f) {
    if (f.is_null()) return std::nullopt;
    return f.as<double>();
}

}  // namespace postgres_internal

struct PostgresStore::Connection : pqxx::connection {
    using pqxx::connection::connection;
};

template <class F>
auto PostgresStore::guarded(const char* what, F&& body) {
    try {
        return body();
    } catch (const StoreError&) {
        throw;
    } catch (const pqxx::broken_connection& e) {
        drop_connection();
        throw postgres_internal::Unreachable(name_ + ": lost the server while " + what +
                                             ": " +
                                             postgres_internal::first_line(e.what()));
    } catch (const pqxx::in_doubt_error& e) {
        drop_connection();
        throw postgres_internal::Unreachable(
            name_ + ": lost the server during a commit (" + what +
            "): " + postgres_internal::first_line(e.what()));
    } catch (const pqxx::sql_error& e) {
        if (postgres_internal::is_connection_state(e.sqlstate()) || !conn_ ||
            !conn_->is_open()) {
            drop_connection();
            throw postgres_internal::Unreachable(name_ + ": lost the server while " +
                                                 what + ": " +
                                                 postgres_internal::first_line(e.what()));
        }
        throw StoreError(name_ + ": " + what + ": " +
                         postgres_internal::first_line(e.what()));
    } catch (const pqxx::failure& e) {
        drop_connection();
        throw postgres_internal::Unreachable(name_ + ": " + what + ": " +
                                             postgres_internal::first_line(e.what()));
    }
}

}  // namespace lucent::study
