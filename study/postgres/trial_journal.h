#pragma once
// A station's local journal (an SQLite file) of trials recorded for a server but not yet
// confirmed by it. A trial is committed here (synchronous=FULL) before the server is
// tried, so the network or the server may fail at any moment without losing a rating;
// it leaves the journal only once the server's transaction holding it has committed.
// Resends are matched on the trial's UUID, so a trial whose commit reply was lost is
// recognised, never stored twice.
// A trial carries its whole outcome: responses, and an adjust or staircase trial's final
// value, adjustments, intensity and whether it finished its staircase (journal version
// 1; an older journal file gains these columns when opened), so a resend stores exactly
// what a direct send would have.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "study/sqlite/database.h"
#include "study/store_types.h"

namespace lucent::study {

struct JournaledTrial {
    std::string trial_uuid;
    std::string session_uuid;
    std::string recorded_utc;  // when the station recorded it (the trial's answered_utc)
    TrialOutcome outcome;
};

class TrialJournal {
public:
    // Held while trials of a journal are sent to the server (a new trial, the older ones
    // flushed before it, `store sync`): an exclusive flock on PATH.send-lock. Every
    // station and process on this machine that uses the journal (two stations of one
    // server on one machine share it) takes turns, so each session's trials reach the
    // server in the order they were recorded, oldest first, and no trial is sent by two
    // stations at once. Each lock opens the file anew, so two stores or threads of one
    // process take turns too; released by the destructor, or by the kernel when the
    // process dies. Throws StoreError naming the file when it cannot be opened.
    class SendLock {
    public:
        explicit SendLock(const TrialJournal& journal);
        ~SendLock();
        SendLock(const SendLock&) = delete;
        SendLock& operator=(const SendLock&) = delete;

    private:
        int fd_ = -1;
    };

    // Opens or creates the journal for `server` (the URI without password). Throws
    // StoreError naming the file when it is another kind of file.
    TrialJournal(const std::string& path, const std::string& server);

    bool contains(const std::string& trial_uuid);
    void add(const JournaledTrial& trial);  // committed when it returns
    void remove(const std::string& trial_uuid);
    // This server's pending trials, oldest first.
    std::vector<JournaledTrial> pending();
    // The pending trial `trial_uuid` (whatever its server), or nullopt.
    std::optional<JournaledTrial> find(const std::string& trial_uuid);
    int count();
    const std::string& path() const { return db_.path(); }

private:
    // The pending trials `where` (one "?" bound to `key`) selects, oldest first, with
    // their responses and adjustments.
    std::vector<JournaledTrial> read(const std::string& where, const std::string& key);

    Database db_;
    std::string server_;
};

// $LUCENT_JOURNAL_DIR, else $XDG_STATE_HOME/lucent, else ~/.local/state/lucent, then
// journal-<first 16 hex digits of sha256(server)>.db: one journal per server and machine
// (and user), shared by every station of that server on the machine, so that `lucent
// store sync` and any later session find what a stopped station left; sending from it is
// serialised by TrialJournal::SendLock.
std::string default_journal_path(const std::string& server);

}  // namespace lucent::study
