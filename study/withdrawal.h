#pragma once
// Withdrawals that stay withdrawn (schema 5). `participants withdraw` deletes a person's
// rows and leaves tombstones in the same transaction: each withdrawn session's UUID, and
// each (code, machine) the person was enrolled under as a salted SHA-256 (the code itself
// is not kept). Merge, merge into a server and `store sync` read the tombstones of every
// database they see and never add a session they cover. Declined consents (schema 9)
// keep the participant code the same way (salted_code below).
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "study/sqlite/database.h"

namespace lucent::study {

// The code a session was enrolled under on its station: merge names people it keeps
// apart CODE@MACHINE or CODE@MACHINE#N (MACHINE a prefix of the machine id, or
// "unknown-machine" for an empty one); that suffix is dropped when it names this
// session's machine. Any other code is returned as it is.
std::string enrolled_code(const std::string& code, const std::string& machine_id);
// True for CODE@MACHINE#N: one of several people merge found under one code on one
// machine.
bool is_split_on_one_machine(const std::string& code, const std::string& machine_id);

// Lower-case hex SHA-256 of salt + code + "\n" + machine_id.
std::string salted_code_hash(const std::string& salt, const std::string& code,
                             const std::string& machine_id);
// 32 hex digits from the system's random device: a fresh salt for each kept code.
std::string random_salt();

// A participant code kept without the code: a fresh random salt and
// salted_code_hash(salt, code, "") (declined_codes, schema 9).
struct SaltedCode {
    std::string salt, code_hash;
};
SaltedCode salted_code(const std::string& code);
// The row of `held` that is `code`'s (each row's hash taken again under its own salt);
// nullopt when none is.
std::optional<SaltedCode> find_salted_code(const std::vector<SaltedCode>& held,
                                           const std::string& code);

// The most participant codes of one study kept as having declined consent. One row per
// code bounds what one person (or one script reusing a code) adds; this bounds a script
// posting fresh codes: past it a decline adds nothing, and the figure reads "at least
// kMaxDeclinedCodes" (declined_consent_figure, export.h). Finding a code hashes each
// row again under its own salt, so the cap also bounds a decline's cost.
inline constexpr int kMaxDeclinedCodes = 1000;

struct WithdrawnCode {
    std::string salt, code_hash, withdrawn_utc;
};

// The tombstones to write when withdrawing `code` whose sessions are `sessions`
// ((uuid, machine_id) each): one row per session UUID, and one code row per machine
// (machine "" when there is no session), each with a fresh random salt. A code merge
// split on one machine (CODE@MACHINE#N) gets no code row: another person holds the
// same code on that machine, so only the UUIDs carry this withdrawal.
std::vector<WithdrawnCode> code_tombstones(
    const std::string& code,
    const std::vector<std::pair<std::string, std::string>>& sessions,
    const std::string& withdrawn_utc);

// Every tombstone of some databases, and the test against them.
class Tombstones {
public:
    // Adds a database's tombstones (none before schema 5).
    void read(Database& db);
    void add_session(const std::string& uuid, const std::string& withdrawn_utc);
    void add_code(const WithdrawnCode& code);

    // A session is withdrawn when its UUID is tombstoned, or its (enrolled code, machine)
    // matches a code tombstone and it started before that withdrawal (a later session
    // under the same code on that machine is someone else). For a participant without
    // sessions pass uuid "" and machine "", with the enrolment time as started_utc.
    bool covers(const std::string& uuid, const std::string& code,
                const std::string& machine_id, const std::string& started_utc) const;
    bool empty() const { return sessions_.empty() && codes_.empty(); }

    // Writes every tombstone into `db` (the merge's output), keeping rows already there.
    void write(Database& db) const;
    const std::map<std::string, std::string>& sessions() const { return sessions_; }
    const std::vector<WithdrawnCode>& codes() const { return codes_; }

private:
    std::map<std::string, std::string> sessions_;  // uuid -> earliest withdrawn_utc
    std::vector<WithdrawnCode> codes_;
};

}  // namespace lucent::study
