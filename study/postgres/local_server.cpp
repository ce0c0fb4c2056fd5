// A throwaway local PostgreSQL server (local_server.h).
#include "study/postgres/local_server.h"

#include <fcntl.h>
#include <pwd.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <pqxx/pqxx>
#include <vector>

#include "study/sqlite/database.h"

namespace lucent::study {

std::string LocalPostgres::binary_dir() {
    namespace fs = std::filesystem;
    if (const char* b = std::getenv("LUCENT_PG_BIN"); b && *b) return b;
    std::error_code ec;
    std::string best;
    for (const auto& entry : fs::directory_iterator("/usr/lib/postgresql", ec)) {
        const fs::path bin = entry.path() / "bin";
        if (fs::exists(bin / "initdb", ec) && bin.string() > best) best = bin.string();
    }
    return best;
}

LocalPostgres::LocalPostgres() : bin_(binary_dir()) {
    if (bin_.empty())
        throw StoreError(
            "no PostgreSQL server binaries (install Debian's 'postgresql' package: "
            "scripts/install-deps)");
    std::string pattern =
        (std::filesystem::temp_directory_path() / "lucent-pg-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
        throw StoreError("cannot create a folder for PostgreSQL");
    folder_ = pattern;
    if (geteuid() == 0) {
        const char* user = std::getenv("LUCENT_PG_USER");
        run_as_ = user && *user ? user : "nobody";
        const passwd* pw = getpwnam(run_as_.c_str());
        if (!pw || chown(folder_.c_str(), pw->pw_uid, pw->pw_gid) != 0)
            throw StoreError(folder_ + ": cannot hand the folder to user '" + run_as_ +
                             "'");
    }
    if (run("initdb", {"-D", folder_ + "/data", "-U", "lucent", "--auth=trust", "-E",
                       "UTF8", "--no-sync", "--no-instructions"}) != 0)
        throw StoreError("initdb failed; see " + folder_ + "/server.log");
    start();
}

LocalPostgres::~LocalPostgres() {
    if (running_)
        run("pg_ctl", {"-D", folder_ + "/data", "-m", "immediate", "-w", "stop"});
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
}

void LocalPostgres::start() {
    // Socket only (listen_addresses empty); fsync stays on, as on a real server.
    if (run("pg_ctl", {"-D", folder_ + "/data", "-l", folder_ + "/server.log", "-w", "-o",
                       "-k " + folder_ + " -c listen_addresses= -c max_connections=200",
                       "start"}) != 0)
        throw StoreError("pg_ctl start failed; see " + folder_ + "/server.log");
    running_ = true;
}

void LocalPostgres::stop() {
    if (run("pg_ctl", {"-D", folder_ + "/data", "-m", "fast", "-w", "stop"}) != 0)
        throw StoreError("pg_ctl stop failed; see " + folder_ + "/server.log");
    running_ = false;
}

std::string LocalPostgres::uri(const std::string& database) const {
    return "postgresql://lucent@/" + database + "?host=" + folder_;
}

std::string LocalPostgres::create_database(const std::string& name) {
    try {
        pqxx::connection c(uri("postgres"));
        pqxx::nontransaction n(c);
        n.exec("CREATE DATABASE " + c.quote_name(name));  // no parameters for identifiers
    } catch (const std::exception& e) {
        throw StoreError("CREATE DATABASE " + name + ": " + e.what());
    }
    return uri(name);
}

int LocalPostgres::run(const std::string& tool,
                       const std::vector<std::string>& args) const {
    std::vector<std::string> argv;
    if (!run_as_.empty()) argv = {"/usr/sbin/runuser", "-u", run_as_, "--"};
    argv.push_back(bin_ + "/" + tool);
    argv.insert(argv.end(), args.begin(), args.end());
    const std::string log = folder_ + "/commands.log";
    std::vector<char*>
        raw;  // built before fork: the child only calls async-signal-safe code
    for (std::string& a : argv) raw.push_back(a.data());
    raw.push_back(nullptr);
    const pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0666);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        if (chdir(folder_.c_str()) != 0) _exit(126);
        execv(raw[0], raw.data());
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace lucent::study
