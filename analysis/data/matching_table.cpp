#include "analysis/data/matching_table.h"

#include <map>
#include <set>

#include "analysis/data/long_table.h"
#include "study/export.h"
#include "study/schema.h"
#include "study/sqlite/database.h"
#include "study/sqlite/database_file.h"

namespace lucent::analysis {
namespace {

using study::Database;
using study::Statement;

bool has_table(Database& db, const std::string& name) {
    return db.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = '" + name +
                         "'") > 0;
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
        table.protocol = study::stored_protocol(db);
        std::string rule = sessions;
        if (rule.empty())
            rule = table.protocol ? table.protocol->analysis.sessions : "completed";
        if (rule != "completed" && rule != "all")
            throw InputError(
                "analysis sessions: expected \"completed\" or \"all\", got '" + rule +
                "'");
        if (version < 7) return table;  // no adjust or staircase trials before schema 7
        const study::SessionSelection taken =
            study::select_sessions(db, db_path, rule, /*exclude_failed_catch=*/true);
        table.excluded_participants = taken.excluded_participants;
        table.sessions_note = taken.note;
        const std::string kind = study::trial_kind_sql(version, "t");
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
                if (!taken.keeps(s.integer(9)) || s.is_null(6)) continue;
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
            if (!taken.keeps(s.integer(10)) || s.is_null(6) || s.is_null(7)) continue;
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
