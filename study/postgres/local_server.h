#pragma once
// A throwaway PostgreSQL server for tests and `lucent bench store`: Debian's binaries
// (/usr/lib/postgresql/<version>/bin, or $LUCENT_PG_BIN), `initdb` into a fresh temporary
// folder and `pg_ctl` listening only on a Unix socket in that folder (no TCP port, so
// nothing outside this machine, and no other user without access to the folder, can
// connect; trust authentication is then safe).
//
// PostgreSQL refuses to run as root. When this process is root (CI containers), the
// folder is handed to the unprivileged user `nobody` (or $LUCENT_PG_USER) and every
// server command runs through `runuser -u USER --`; otherwise it runs as the caller.
#include <atomic>
#include <string>
#include <vector>

namespace lucent::study {

class LocalPostgres {
public:
    // initdb + start; throws StoreError (one line, naming the log) on failure.
    LocalPostgres();
    ~LocalPostgres();  // stops the server and removes the folder
    LocalPostgres(const LocalPostgres&) = delete;
    LocalPostgres& operator=(const LocalPostgres&) = delete;

    void start();
    void stop();  // fast shutdown: sessions are disconnected, committed data stays
    bool running() const { return running_; }
    // A new empty database; returns its URI (postgresql://lucent@/NAME?host=SOCKET_DIR).
    std::string create_database(const std::string& name);
    std::string uri(const std::string& database) const;
    const std::string& folder() const { return folder_; }

    // Where Debian's server binaries are; "" when none are installed.
    static std::string binary_dir();

private:
    int run(const std::string& tool, const std::vector<std::string>& args) const;

    std::string bin_;
    std::string folder_;
    std::string run_as_;  // "" = this user
    std::atomic<bool> running_{false};
};

}  // namespace lucent::study
