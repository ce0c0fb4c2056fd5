// The station's journal of unconfirmed trials (trial_journal.h).
#include "study/postgres/trial_journal.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "study/schema.h"
#include "study/sha256.h"

namespace lucent::study {
namespace {

constexpr int32_t kJournalApplicationId = 0x4C55434A;  // "LUCJ"

// Journal version 1 (PRAGMA user_version; 0 before): what an adjust or staircase trial
// carries besides its responses (schema 7). A journal of version 0 gains the columns and
// the table when opened (upgrade_journal), its pending trials kept.
constexpr int kJournalVersion = 1;

const char* const kJournalSchema = R"sql(
CREATE TABLE IF NOT EXISTS pending_trials (
    trial_uuid TEXT PRIMARY KEY,
    server TEXT NOT NULL,
    session_uuid TEXT NOT NULL,
    recorded_utc TEXT NOT NULL,
    onset_ns INTEGER NOT NULL,
    confirm_ns INTEGER NOT NULL,
    dropped_frames INTEGER,
    seq INTEGER NOT NULL,
    final_value REAL,
    intensity REAL,
    finishes_staircase INTEGER NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS pending_responses (
    trial_uuid TEXT NOT NULL REFERENCES pending_trials(trial_uuid) ON DELETE CASCADE,
    question TEXT NOT NULL,
    rating INTEGER NOT NULL,
    rt_ms REAL NOT NULL,
    changes INTEGER NOT NULL,
    first_choice_ns INTEGER NOT NULL,
    final_choice_ns INTEGER NOT NULL,
    PRIMARY KEY (trial_uuid, question));
CREATE TABLE IF NOT EXISTS pending_adjustments (
    trial_uuid TEXT NOT NULL REFERENCES pending_trials(trial_uuid) ON DELETE CASCADE,
    step INTEGER NOT NULL,
    value REAL NOT NULL,
    t_ns INTEGER NOT NULL,
    input TEXT NOT NULL,
    PRIMARY KEY (trial_uuid, step));
)sql";

// The columns version 1 added to pending_trials, as ALTER TABLE adds them.
const char* const kVersion1Columns[][2] = {
    {"final_value", "REAL"},
    {"intensity", "REAL"},
    {"finishes_staircase", "INTEGER NOT NULL DEFAULT 0"}};

// Brings a journal of an older version to kJournalVersion, under the write lock (two
// stations opening one journal at once upgrade it once).
void upgrade_journal(Database& db) {
    if (db.scalar_int("PRAGMA user_version") >= kJournalVersion) return;
    Transaction tx(db);
    if (db.scalar_int("PRAGMA user_version") >= kJournalVersion) return;
    for (const auto& [name, type] : kVersion1Columns) {
        Statement has = db.prepare(
            "SELECT count(*) FROM pragma_table_info('pending_trials') WHERE name = ?");
        has.bind(1, name);
        if (has.step() && has.integer(0) == 0)
            db.exec(std::string("ALTER TABLE pending_trials ADD COLUMN ") + name + " " +
                    type);
    }
    db.exec(kJournalSchema);  // the new tables (IF NOT EXISTS)
    db.exec("PRAGMA user_version = " + std::to_string(kJournalVersion));
    tx.commit();
}

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
        db_.exec("PRAGMA user_version = " + std::to_string(kJournalVersion));
        tx.commit();
    } else if (app != kJournalApplicationId) {
        throw StoreError(path + ": not a Lucent trial journal; left unchanged");
    }
    upgrade_journal(db_);
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
           "onset_ns, confirm_ns, dropped_frames, seq, final_value, intensity, "
           "finishes_staircase) VALUES (?, ?, ?, ?, ?, ?, ?, "
           "(SELECT coalesce(max(seq), 0) + 1 FROM pending_trials), ?, ?, ?)")
        .bind(1, t.trial_uuid)
        .bind(2, server_)
        .bind(3, t.session_uuid)
        .bind(4, t.recorded_utc)
        .bind(5, t.outcome.onset_ns)
        .bind(6, t.outcome.confirm_ns)
        .bind(7, t.outcome.dropped_frames)
        .bind(8, t.outcome.final_value)
        .bind(9, t.outcome.intensity)
        .bind(10, t.outcome.finishes_staircase ? 1 : 0)
        .run();
    Statement a = db_.prepare(
        "INSERT INTO pending_adjustments (trial_uuid, step, value, t_ns, input) VALUES "
        "(?, ?, ?, ?, ?)");
    for (size_t k = 0; k < t.outcome.adjustments.size(); ++k) {
        const Adjustment& x = t.outcome.adjustments[k];
        a.reset();
        a.bind(1, t.trial_uuid)
            .bind(2, static_cast<int64_t>(k + 1))
            .bind(3, x.value)
            .bind(4, x.t_ns)
            .bind(5, x.input)
            .run();
    }
    Statement r =
        db_.prepare("INSERT INTO pending_responses (trial_uuid, " +
                    std::string(kResponseColumns) + ") VALUES (?, ?, ?, ?, ?, ?, ?)");
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

std::vector<JournaledTrial> TrialJournal::read(const std::string& where,
                                               const std::string& key) {
    std::vector<JournaledTrial> out;
    Statement s = db_.prepare(
        "SELECT trial_uuid, session_uuid, recorded_utc, onset_ns, confirm_ns, "
        "dropped_frames, final_value, intensity, finishes_staircase "
        "FROM pending_trials WHERE " +
        where + " ORDER BY seq");
    s.bind(1, key);
    while (s.step()) {
        JournaledTrial t;
        t.trial_uuid = s.text(0);
        t.session_uuid = s.text(1);
        t.recorded_utc = s.text(2);
        t.outcome.onset_ns = s.integer(3);
        t.outcome.confirm_ns = s.integer(4);
        if (!s.is_null(5)) t.outcome.dropped_frames = static_cast<int>(s.integer(5));
        t.outcome.final_value = s.optional_real(6);
        t.outcome.intensity = s.optional_real(7);
        t.outcome.finishes_staircase = s.integer(8) != 0;
        out.push_back(std::move(t));
    }
    Statement r =
        db_.prepare("SELECT " + std::string(kResponseColumns) +
                    " FROM pending_responses WHERE trial_uuid = ? ORDER BY question");
    Statement a = db_.prepare(
        "SELECT value, t_ns, input FROM pending_adjustments WHERE trial_uuid = ? ORDER "
        "BY step");
    for (JournaledTrial& t : out) {
        r.reset();
        r.bind(1, t.trial_uuid);
        while (r.step())
            t.outcome.responses.push_back({r.text(0), static_cast<int>(r.integer(1)),
                                           r.real(2), static_cast<int>(r.integer(3)),
                                           r.integer(4), r.integer(5)});
        a.reset();
        a.bind(1, t.trial_uuid);
        while (a.step())
            t.outcome.adjustments.push_back({a.real(0), a.integer(1), a.text(2)});
    }
    return out;
}

std::vector<JournaledTrial> TrialJournal::pending() {
    return read("server = ?", server_);
}

std::optional<JournaledTrial> TrialJournal::find(const std::string& trial_uuid) {
    std::vector<JournaledTrial> found = read("trial_uuid = ?", trial_uuid);
    if (found.empty()) return std::nullopt;
    return std::move(found.front());
}

int TrialJournal::count() {
    Statement s = db_.prepare("SELECT count(*) FROM pending_trials WHERE server = ?");
    s.bind(1, server_);
    return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

}  // namespace lucent::study
