// The station's journal of unconfirmed trials (trial_journal.h).
#include "study/postgres/trial_journal.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "study/sha256.h"

namespace lucent::study {
namespace {

constexpr int32_t kJournalApplicationId = 0x4C55434A;  // "LUCJ"

const char* const kJournalSchema = R"sql(
CREATE TABLE IF NOT EXISTS pending_trials (
    trial_uuid TEXT PRIMARY KEY,
    server TEXT NOT NULL,
    session_uuid TEXT NOT NULL,
    recorded_utc TEXT NOT NULL,
    onset_ns INTEGER NOT NULL,
    confirm_ns INTEGER NOT NULL,
    dropped_frames INTEGER,
    seq INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS pending_responses (
    trial_uuid TEXT NOT NULL REFERENCES pending_trials(trial_uuid) ON DELETE CASCADE,
    question TEXT NOT NULL,
    rating INTEGER NOT NULL,
    rt_ms REAL NOT NULL,
    changes INTEGER NOT NULL,
    first_choice_ns INTEGER NOT NULL,
    final_choice_ns INTEGER NOT NULL,
    PRIMARY KEY (trial_uuid, question));
)sql";

std::string state_dir() {
    if (const char* d = std::getenv("LUCENT_JOURNAL_DIR"); d && *d) return d;
    if (const char* d = std::getenv("XDG_STATE_HOME"); d && *d)
        return std::string(d) + "/lucent";
    if (const char* h = std::getenv("HOME"); h && *h)
        return std::string(h) + "/.local/state/lucent";
    return ".";
}

}  // namespace

std::string default_journal_path(const std::string& server) {
    return state_dir() + "/journal-" + sha256_hex(server).substr(0, 16) + ".db";
}

TrialJournal::TrialJournal(const std::string& path, const std::string& server)
    : db_((
              [&] {
                  std::error_code ec;
                  const auto parent = std::filesystem::path(path).parent_path();
                  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
              }(),
              path),
          SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE),
      server_(server) {
    db_.exec("PRAGMA journal_mode = WAL");
    db_.exec("PRAGMA synchronous = FULL");
    db_.exec("PRAGMA foreign_keys = ON");
    const int64_t app = db_.scalar_int("PRAGMA application_id");
    if (app == 0 && db_.scalar_int("SELECT count(*) FROM sqlite_schema") == 0) {
        Transaction tx(db_);
        db_.exec(kJournalSchema);
        db_.exec("PRAGMA application_id = " + std::to_string(kJournalApplicationId));
        tx.commit();
    } else if (app != kJournalApplicationId) {
        throw StoreError(path + ": not a Lucent trial journal; left unchanged");
    }
}

TrialJournal::SendLock::SendLock(const TrialJournal& journal) {
    const std::string path = journal.path() + ".send-lock";
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (fd_ < 0)
        throw StoreError(
            path + ": cannot open the journal's send lock: " + std::strerror(errno));
    while (::flock(fd_, LOCK_EX) != 0) {
        if (errno == EINTR) continue;
        const int error = errno;
        ::close(fd_);
        fd_ = -1;
        throw StoreError(
            path + ": cannot lock the journal for sending: " + std::strerror(error));
    }
}

TrialJournal::SendLock::~SendLock() {
    if (fd_ >= 0) ::close(fd_);  // closing the only descriptor releases the flock
}

bool TrialJournal::contains(const std::string& trial_uuid) {
    Statement s = db_.prepare("SELECT count(*) FROM pending_trials WHERE trial_uuid = ?");
    s.bind(1, trial_uuid);
    return s.step() && s.integer(0) > 0;
}

void TrialJournal::add(const JournaledTrial& t) {
    Transaction tx(db_);
    db_.prepare(
           "INSERT INTO pending_trials (trial_uuid, server, session_uuid, recorded_utc, "
           "onset_ns, confirm_ns, dropped_frames, seq) VALUES (?, ?, ?, ?, ?, ?, ?, "
           "(SELECT coalesce(max(seq), 0) + 1 FROM pending_trials))")
        .bind(1, t.trial_uuid)
        .bind(2, server_)
        .bind(3, t.session_uuid)
        .bind(4, t.recorded_utc)
        .bind(5, t.outcome.onset_ns)
        .bind(6, t.outcome.confirm_ns)
        .bind(7, t.outcome.dropped_frames)
        .run();
    Statement r = db_.prepare(
        "INSERT INTO pending_responses (trial_uuid, question, rating, rt_ms, changes, "
        "first_choice_ns, final_choice_ns) VALUES (?, ?, ?, ?, ?, ?, ?)");
    for (const Response& x : t.outcome.responses) {
        r.reset();
        r.bind(1, t.trial_uuid)
            .bind(2, x.question)
            .bind(3, x.rating)
            .bind(4, x.rt_ms)
            .bind(5, x.changes)
            .bind(6, x.first_choice_ns)
            .bind(7, x.final_choice_ns)
            .run();
    }
    tx.commit();
}

void TrialJournal::remove(const std::string& trial_uuid) {
    db_.prepare("DELETE FROM pending_trials WHERE trial_uuid = ?")
        .bind(1, trial_uuid)
        .run();
}

std::vector<JournaledTrial> TrialJournal::pending() {
    std::vector<JournaledTrial> out;
    Statement s = db_.prepare(
        "SELECT trial_uuid, session_uuid, recorded_utc, onset_ns, confirm_ns, "
        "dropped_frames "
        "FROM pending_trials WHERE server = ? ORDER BY seq");
    s.bind(1, server_);
    while (s.step()) {
        JournaledTrial t;
        t.trial_uuid = s.text(0);
        t.session_uuid = s.text(1);
        t.recorded_utc = s.text(2);
        t.outcome.onset_ns = s.integer(3);
        t.outcome.confirm_ns = s.integer(4);
        if (!s.is_null(5)) t.outcome.dropped_frames = static_cast<int>(s.integer(5));
        out.push_back(std::move(t));
    }
    Statement r = db_.prepare(
        "SELECT question, rating, rt_ms, changes, first_choice_ns, final_choice_ns "
        "FROM pending_responses WHERE trial_uuid = ? ORDER BY question");
    for (JournaledTrial& t : out) {
        r.reset();
        r.bind(1, t.trial_uuid);
        while (r.step())
            t.outcome.responses.push_back({r.text(0), static_cast<int>(r.integer(1)),
                                           r.real(2), static_cast<int>(r.integer(3)),
                                           r.integer(4), r.integer(5)});
    }
    return out;
}

int TrialJournal::count() {
    Statement s = db_.prepare("SELECT count(*) FROM pending_trials WHERE server = ?");
    s.bind(1, server_);
    return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

}  // namespace lucent::study
