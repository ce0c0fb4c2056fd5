// Withdrawal tombstones (withdrawal.h).
#include "study/withdrawal.h"

#include <cstdio>
#include <random>
#include <set>

#include "study/sha256.h"

namespace lucent::study {
namespace {

// Splits CODE@LABEL[#N] where LABEL names `machine_id`; returns (base, had #N) or
// ("", false) when the code carries no such suffix.
std::pair<std::string, bool> split_suffix(const std::string& code,
                                          const std::string& machine_id) {
    const size_t at = code.rfind('@');
    if (at == std::string::npos || at == 0) return {"", false};
    std::string label = code.substr(at + 1);
    bool numbered = false;
    const size_t hash = label.rfind('#');
    if (hash != std::string::npos && hash + 1 < label.size() &&
        label.find_first_not_of("0123456789", hash + 1) == std::string::npos) {
        label = label.substr(0, hash);
        numbered = true;
    }
    const bool names_machine = machine_id.empty()
                                   ? label == "unknown-machine"
                                   : label.size() >= 8 && machine_id.rfind(label, 0) == 0;
    if (!names_machine) return {"", false};
    return {code.substr(0, at), numbered};
}

}  // namespace

std::string random_salt() {
    std::random_device device;
    char out[40];
    std::snprintf(out, sizeof out, "%08x%08x%08x%08x", device(), device(), device(),
                  device());
    return out;
}

std::string enrolled_code(const std::string& code, const std::string& machine_id) {
    const auto [base, numbered] = split_suffix(code, machine_id);
    (void)numbered;
    return base.empty() ? code : base;
}

bool is_split_on_one_machine(const std::string& code, const std::string& machine_id) {
    const auto [base, numbered] = split_suffix(code, machine_id);
    return !base.empty() && numbered;
}

std::string salted_code_hash(const std::string& salt, const std::string& code,
                             const std::string& machine_id) {
    return sha256_hex(salt + code + "\n" + machine_id);
}

SaltedCode salted_code(const std::string& code) {
    const std::string salt = random_salt();
    return {salt, salted_code_hash(salt, code, "")};
}

std::optional<SaltedCode> find_salted_code(const std::vector<SaltedCode>& held,
                                           const std::string& code) {
    for (const SaltedCode& row : held)
        if (salted_code_hash(row.salt, code, "") == row.code_hash) return row;
    return std::nullopt;
}

std::vector<WithdrawnCode> code_tombstones(
    const std::string& code,
    const std::vector<std::pair<std::string, std::string>>& sessions,
    const std::string& withdrawn_utc) {
    std::set<std::string> machines;
    for (const auto& [uuid, machine] : sessions) {
        if (is_split_on_one_machine(code, machine)) return {};
        machines.insert(machine);
    }
    if (sessions.empty()) machines.insert("");
    std::vector<WithdrawnCode> out;
    for (const std::string& machine : machines) {
        const std::string salt = random_salt();
        out.push_back({salt,
                       salted_code_hash(salt, enrolled_code(code, machine), machine),
                       withdrawn_utc});
    }
    return out;
}

void Tombstones::read(Database& db) {
    if (db.scalar_int(
            "SELECT count(*) FROM sqlite_schema WHERE name = 'withdrawn_sessions'") == 0)
        return;
    Statement s = db.prepare("SELECT uuid, withdrawn_utc FROM withdrawn_sessions");
    while (s.step()) add_session(s.text(0), s.text(1));
    Statement c =
        db.prepare("SELECT salt, code_hash, withdrawn_utc FROM withdrawn_codes");
    while (c.step()) add_code({c.text(0), c.text(1), c.text(2)});
}

void Tombstones::add_session(const std::string& uuid, const std::string& withdrawn_utc) {
    const auto [it, is_new] = sessions_.try_emplace(uuid, withdrawn_utc);
    if (!is_new && withdrawn_utc < it->second) it->second = withdrawn_utc;
}

void Tombstones::add_code(const WithdrawnCode& code) {
    for (WithdrawnCode& held : codes_)
        if (held.salt == code.salt && held.code_hash == code.code_hash) {
            if (code.withdrawn_utc < held.withdrawn_utc)
                held.withdrawn_utc = code.withdrawn_utc;
            return;
        }
    codes_.push_back(code);
}

bool Tombstones::covers(const std::string& uuid, const std::string& code,
                        const std::string& machine_id,
                        const std::string& started_utc) const {
    if (!uuid.empty() && sessions_.count(uuid)) return true;
    if (codes_.empty()) return false;
    const std::string enrolled = enrolled_code(code, machine_id);
    for (const WithdrawnCode& c : codes_)
        if (started_utc < c.withdrawn_utc &&
            salted_code_hash(c.salt, enrolled, machine_id) == c.code_hash)
            return true;
    return false;
}

void Tombstones::write(Database& db) const {
    Statement s = db.prepare(
        "INSERT INTO withdrawn_sessions (uuid, withdrawn_utc) VALUES (?, ?) ON CONFLICT "
        "(uuid) "
        "DO UPDATE SET withdrawn_utc = min(withdrawn_utc, excluded.withdrawn_utc)");
    for (const auto& [uuid, utc] : sessions_) {
        s.reset();
        s.bind(1, uuid).bind(2, utc).run();
    }
    Statement c = db.prepare(
        "INSERT INTO withdrawn_codes (salt, code_hash, withdrawn_utc) VALUES (?, ?, ?) "
        "ON CONFLICT (salt, code_hash) DO UPDATE SET "
        "withdrawn_utc = min(withdrawn_utc, excluded.withdrawn_utc)");
    for (const WithdrawnCode& code : codes_) {
        c.reset();
        c.bind(1, code.salt).bind(2, code.code_hash).bind(3, code.withdrawn_utc).run();
    }
}

}  // namespace lucent::study
