#include "analysis/data/matching_table.h"

#include <map>
#include <set>

#include "analysis/data/long_table.h"
#include "study/schema.h"
#include "study/sqlite/database.h"
#include "study/sqlite/database_file.h"

namespace lucent::analysis {
namespace {

using study::Database;
using study::Statement;

std::optional<study::Protocol> stored_protocol(Database& db) {
    Statement s = db.prepare("SELECT protocol_text FROM studies LIMIT 1");
    if (!s.step()) return std::nullopt;
    try {
        return study::parse_protocol(s.text(0), db.path() + " (stored protocol)", "",
                                     study::KnobCheck::lenient);
    } catch (const study::ProtocolError&) {
        return std::nullopt;
    }
}

bool has_table(Database& db, const std::string& name) {
    return db.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = '" + name +
                         "'") > 0;
}

// The sessions the analysis takes, as study/export.cpp's readers decide: withdrawn
// never, "completed" only completed ones, participants over the protocol's allowance of
// failed catch trials left out.
struct Taken {
    std::map<int64_t, std::string> sessions;  // session id -> participant code
    std::set<std::string> excluded;
};

Taken take_sessions(Database& db, const std::string& db_path, const std::string& rule,
                    int allowed_failures, MatchingTable& table) {
    Taken out;
    std::set<std::string> withdrawn;
    if (has_table(db, "withdrawn_sessions")) {
        Statement w = db.prepare("SELECT uuid FROM withdrawn_sessions");
        while (w.step()) withdrawn.insert(w.text(0));
    }
    int total = static_cast<int>(withdrawn.size()), incomplete = 0, failed_catch = 0;
    std::map<std::string, int> by_status;
    {
        Statement q = db.prepare(
            "SELECT se.id, se.uuid, se.status, p.code FROM sessions se "
            "JOIN participants p ON p.id = se.participant_id ORDER BY se.id");
        while (q.step()) {
            if (withdrawn.count(q.text(1))) continue;
            ++total;
            if (rule == "completed" && q.text(2) != "completed") {
                ++incomplete;
                ++by_status[q.text(2)];
                continue;
            }
            out.sessions[q.integer(0)] = q.text(3);
        }
    }
    std::map<std::string, int> failed;
    Statement f = db.prepare(
        "SELECT r.session_id, count(DISTINCT t.id) FROM responses r "
        "JOIN trials t ON t.id = r.trial_id "
        "WHERE t.catch = 1 AND abs(r.rating - t.expected_rating) > "
        "coalesce(t.tolerance, 0) GROUP BY r.session_id");
    while (f.step()) {
        const auto it = out.sessions.find(f.integer(0));
        if (it != out.sessions.end())
            failed[it->second] += static_cast<int>(f.integer(1));
    }
    for (const auto& [participant, n] : failed)
        if (n > allowed_failures) {
            out.excluded.insert(participant);
            table.excluded_participants.push_back(participant + " (" + std::to_string(n) +
                                                  " catch trials failed)");
        }
    for (const auto& [id, participant] : out.sessions)
        if (out.excluded.count(participant)) ++failed_catch;
    const int analysed = static_cast<int>(out.sessions.size()) - failed_catch;
    std::string note =
        db_path + ": " + std::to_string(analysed) + " of " + std::to_string(total) +
        " sessions analysed (" +
        (rule == "completed" ? "completed sessions only, the analysis plan's default"
                             : "sessions of every status, as the analysis plan says") +
        "); left out: " + std::to_string(incomplete) + " incomplete";
    if (!by_status.empty()) {
        note += " (";
        bool first = true;
        for (const auto& [status, n] : by_status) {
            note += (first ? "" : ", ") + std::to_string(n) + " " + status;
            first = false;
        }
        note += ")";
    }
    note += ", " + std::to_string(failed_catch) + " failed catch trials, " +
            std::to_string(static_cast<int>(withdrawn.size())) + " withdrawn";
    table.sessions_note = note;
    return out;
}

}  // namespace

MatchingTable read_matching_table(const std::string& db_path,
                                  const std::string& sessions) {
    MatchingTable table;
    try {
        study::check_database_file(db_path);
        Database db(db_path, SQLITE_OPEN_READONLY);
        if (!has_table(db, "responses") || !has_table(db, "sessions")) return table;
        const int version = static_cast<int>(db.scalar_int("PRAGMA user_version"));
        table.protocol = stored_protocol(db);
        std::string rule = sessions;
        if (rule.empty())
            rule = table.protocol ? table.protocol->analysis.sessions : "completed";
        if (rule != "completed" && rule != "all")
            throw InputError(
                "analysis sessions: expected \"completed\" or \"all\", got '" + rule +
                "'");
        if (version < 7) return table;  // no adjust or staircase trials before schema 7
        const Taken taken =
            take_sessions(db, db_path, rule,
                          table.protocol ? table.protocol->max_failed_catch : 0, table);
        const std::string kind = study::trial_kind_sql(version, "t");
        auto keep = [&](int64_t session, const std::string& participant) {
            return taken.sessions.count(session) && !taken.excluded.count(participant);
        };
        {
            Statement s = db.prepare(
                "SELECT p.code, se.uuid, t.position, t.block, st.stimulus_key, "
                "t.start_value, t.final_value, (SELECT count(*) FROM adjustments a "
                "WHERE a.trial_id = t.id), r.rt_ms, se.id FROM responses r "
                "JOIN trials t ON t.id = r.trial_id JOIN sessions se ON se.id = "
                "r.session_id JOIN participants p ON p.id = se.participant_id "
                "JOIN stimuli st ON st.id = t.stimulus_id "
                "WHERE t.practice = 0 AND " +
                kind + " = 'adjust' ORDER BY p.code, se.id, t.position, r.id");
            while (s.step()) {
                if (!keep(s.integer(9), s.text(0)) || s.is_null(6)) continue;
                MatchRow row;
                row.participant = s.text(0);
                row.session = s.text(1);
                row.trial = static_cast<int>(s.integer(2));
                row.block = s.text(3);
                row.target = s.text(4);
                if (table.protocol)
                    if (const study::Block* b = table.protocol->find_block(row.block)) {
                        row.match = b->match;
                        row.knob = b->knob;
                    }
                if (!s.is_null(5)) row.start_value = s.real(5);
                row.final_value = s.real(6);
                row.adjustments = static_cast<int>(s.integer(7));
                row.rt_ms = s.real(8);
                table.matches.push_back(std::move(row));
            }
        }
        Statement s = db.prepare(
            "SELECT p.code, se.uuid, t.position, t.block, st.stimulus_key, "
            "coalesce(t.staircase, ''), t.intensity, t.expected_rating, r.rating, "
            "r.rt_ms, se.id FROM responses r "
            "JOIN trials t ON t.id = r.trial_id JOIN sessions se ON se.id = r.session_id "
            "JOIN participants p ON p.id = se.participant_id "
            "JOIN stimuli st ON st.id = t.stimulus_id "
            "WHERE t.practice = 0 AND " +
            kind + " = 'staircase' ORDER BY p.code, se.id, t.position, r.id");
        while (s.step()) {
            if (!keep(s.integer(10), s.text(0)) || s.is_null(6) || s.is_null(7)) continue;
            StaircaseRow row;
            row.participant = s.text(0);
            row.session = s.text(1);
            row.trial = static_cast<int>(s.integer(2));
            row.block = s.text(3);
            row.standard = s.text(4);
            row.staircase = s.text(5);
            row.intensity = s.real(6);
            row.expected = static_cast<int>(s.integer(7));
            row.choice = static_cast<int>(s.integer(8));
            row.correct = row.choice == row.expected;
            row.rt_ms = s.real(9);
            table.staircases.push_back(std::move(row));
        }
    } catch (const study::StoreError& e) {
        throw InputError(e.what());
    }
    return table;
}

}  // namespace lucent::analysis
