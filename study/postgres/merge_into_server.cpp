// Station files into a study server (merge_into_server.h).
#include "study/postgres/merge_into_server.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <pqxx/pqxx>
#include <set>

#include "common/number_text.h"
#include "study/postgres/postgres_store.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/study_store.h"

namespace lucent::study {
namespace {

using IdMap = std::map<int64_t, int64_t>;  // row id in the merged file -> on the server

struct Column {
    std::string name;
    bool real = false;  // declared REAL
};

std::vector<Column> columns_of(Database& m, const std::string& table) {
    std::vector<Column> out;
    Statement s =
        m.prepare("SELECT name, type FROM pragma_table_info(?) WHERE name <> 'id'");
    s.bind(1, table);
    while (s.step()) out.push_back({s.text(0), s.text(1) == "REAL"});
    return out;
}

// Inserts the rows of `table` in the merged file `m` that `where` selects, with each
// column in `remap` translated to the server's ids. Table, column and condition texts are
// this file's constants; every value travels as a parameter. Returns the id map when
// the table has an id column.
IdMap copy_rows(pqxx::work& tx, Database& m, const std::string& table,
                const std::string& where,
                const std::map<std::string, const IdMap*>& remap, bool has_id,
                const std::string& conflict = "") {
    const std::vector<Column> columns = columns_of(m, table);
    std::string names, marks;
    for (size_t c = 0; c < columns.size(); ++c) {
        names += (c ? ", " : "") + columns[c].name;
        marks += (c ? ", $" : "$") + std::to_string(c + 1);
    }
    const std::string insert = "INSERT INTO " + table + " (" + names + ") VALUES (" +
                               marks + ")" + conflict + (has_id ? " RETURNING id" : "");
    Statement rows = m.prepare("SELECT " + std::string(has_id ? "id, " : "0, ") + names +
                               " FROM " + table + " WHERE " + where + " ORDER BY 1");
    IdMap ids;
    while (rows.step()) {
        std::vector<std::optional<std::string>> values;
        for (size_t c = 0; c < columns.size(); ++c) {
            const int col = static_cast<int>(c) + 1;
            if (rows.is_null(col)) {
                values.emplace_back();
                continue;
            }
            const auto mapped = remap.find(columns[c].name);
            if (mapped == remap.end()) {
                // A REAL as its shortest exact text: SQLite's own text keeps 15 digits.
                values.emplace_back(columns[c].real
                                        ? common::shortest_text(rows.real(col))
                                        : rows.text(col));
                continue;
            }
            const auto id = mapped->second->find(rows.integer(col));
            if (id == mapped->second->end())
                throw StoreError("merge: " + table + "." + columns[c].name + " " +
                                 std::to_string(rows.integer(col)) +
                                 " has no row on the server");
            values.emplace_back(std::to_string(id->second));
        }
        const pqxx::result r =
            tx.exec_params(insert, pqxx::prepare::make_dynamic_params(values));
        if (has_id) ids[rows.integer(0)] = r[0][0].as<int64_t>();
    }
    return ids;
}

struct StudyIds {
    IdMap studies, stimuli;
};

// The series pictures the copied segments (`segments_where` over session_segments g)
// name: a set is its hash, so a set the server holds already adds nothing.
void copy_series_pictures(pqxx::work& tx, Database& m, const IdMap& studies,
                          const std::string& segments_where) {
    copy_rows(tx, m, "series_pictures",
              "(study_id, set_hash) IN (SELECT se.study_id, g.series_set FROM "
              "session_segments g JOIN sessions se ON se.id = g.session_id WHERE " +
                  segments_where + ")",
              {{"study_id", &studies}}, false, " ON CONFLICT DO NOTHING");
}

// The server's sessions that a file's copy extends (temp.extended): the status, end
// and consent the kept copy holds (never undoing a completion), its segments the
// server lacks (temp.ext_segments) with what they showed, and each trial answered there
// but not on the server (temp.ext_trials) with its ratings. The server's session keeps
// its id and every row it had.
void extend_server_sessions(pqxx::work& tx, Database& m, const StudyIds& study) {
    const IdMap& stimuli = study.stimuli;
    IdMap sessions, segments, trials;
    Statement e = m.prepare(
        "SELECT e.id, e.uuid, s.status, s.ended_utc, s.consent_utc "
        "FROM temp.extended e JOIN main.sessions s ON s.id = e.id");
    while (e.step()) {
        const pqxx::result held = tx.exec_params(
            "SELECT id FROM sessions WHERE uuid = $1 FOR UPDATE", e.text(1));
        if (held.empty())
            throw StoreError("merge: session " + e.text(1) +
                             " left the server meanwhile (withdrawn?); nothing changed");
        const int64_t id = held[0][0].as<int64_t>();
        sessions[e.integer(0)] = id;
        tx.exec_params(
            "UPDATE sessions SET status = $1, ended_utc = $2, "
            "consent_utc = coalesce(consent_utc, $3) WHERE id = $4 "
            "AND status <> 'completed'",
            e.text(2), e.is_null(3) ? std::optional<std::string>() : e.text(3),
            e.is_null(4) ? std::optional<std::string>() : e.text(4), id);
    }
    if (sessions.empty()) return;
    segments =
        copy_rows(tx, m, "session_segments", "id IN (SELECT id FROM temp.ext_segments)",
                  {{"session_id", &sessions}}, true);
    copy_rows(tx, m, "segment_stimuli",
              "segment_id IN (SELECT id FROM temp.ext_segments)",
              {{"segment_id", &segments}, {"stimulus_id", &stimuli}}, false);
    copy_series_pictures(tx, m, study.studies,
                         "g.id IN (SELECT id FROM temp.ext_segments)");
    // The segments both hold, by number.
    Statement g = m.prepare(
        "SELECT g.id, g.session_id, g.segment FROM main.session_segments g "
        "JOIN temp.extended e ON e.id = g.session_id "
        "WHERE g.id NOT IN (SELECT id FROM temp.ext_segments)");
    while (g.step())
        segments[g.integer(0)] = tx.exec_params1(
                                       "SELECT id FROM session_segments WHERE session_id "
                                       "= $1 AND segment = $2",
                                       sessions.at(g.integer(1)), g.integer(2))[0]
                                     .as<int64_t>();
    Statement t = m.prepare(
        "SELECT t.id, t.session_id, t.position, t.onset_ns, t.confirm_ns, "
        "t.dropped_frames, t.answered_utc, t.segment_id, t.final_value, t.intensity "
        "FROM main.trials t WHERE t.id IN (SELECT id FROM temp.ext_trials)");
    auto optional_int = [&t](int col) {
        return t.is_null(col) ? std::optional<int64_t>()
                              : std::optional<int64_t>(t.integer(col));
    };
    while (t.step()) {
        const int64_t server_session = sessions.at(t.integer(1));
        const int64_t id = tx.exec_params1(
                                 "SELECT id FROM trials WHERE session_id = $1 AND "
                                 "position = $2 FOR UPDATE",
                                 server_session, t.integer(2))[0]
                               .as<int64_t>();
        trials[t.integer(0)] = id;
        std::optional<int64_t> segment;
        if (!t.is_null(7)) segment = segments.at(t.integer(7));
        tx.exec_params(
            "UPDATE trials SET onset_ns = $1, confirm_ns = $2, dropped_frames = $3, "
            "answered_utc = $4, segment_id = $5, final_value = $6, intensity = $7 "
            "WHERE id = $8",
            optional_int(3), optional_int(4), optional_int(5),
            t.is_null(6) ? std::optional<std::string>() : t.text(6), segment,
            t.optional_real(8), t.optional_real(9), id);
    }
    // A station answering the same trial meanwhile makes the insert fail (one rating per
    // trial and question): the whole merge is then not stored.
    copy_rows(tx, m, "responses", "trial_id IN (SELECT id FROM temp.ext_trials)",
              {{"session_id", &sessions}, {"trial_id", &trials}}, false);
    copy_rows(tx, m, "adjustments", "trial_id IN (SELECT id FROM temp.ext_trials)",
              {{"trial_id", &trials}}, false);
    // Staircase slots the file's copy skipped (the reconciling kept a copy extending
    // the server's: a slot is never answered there and skipped here).
    Statement skipped = m.prepare(
        "SELECT t.session_id, t.position FROM main.trials t JOIN temp.extended e ON "
        "e.id = t.session_id WHERE t.skipped = 1");
    while (skipped.step())
        tx.exec_params(
            "UPDATE trials SET skipped = 1 WHERE session_id = $1 AND position = $2",
            sessions.at(skipped.integer(0)), skipped.integer(1));
}

// The tombstones the inputs hold, onto the server; then the server's sessions they
// cover are deleted, and participants left without a session with them (their
// numbers retired), as `participants withdraw` does.
void withdraw_on_server(pqxx::work& tx, Database& m,
                        const std::vector<std::string>& uuids) {
    Statement s = m.prepare("SELECT uuid, withdrawn_utc FROM main.withdrawn_sessions");
    while (s.step())
        tx.exec_params(
            "INSERT INTO withdrawn_sessions (uuid, withdrawn_utc) VALUES ($1, $2) "
            "ON CONFLICT DO NOTHING",
            s.text(0), s.text(1));
    Statement c =
        m.prepare("SELECT salt, code_hash, withdrawn_utc FROM main.withdrawn_codes");
    while (c.step())
        tx.exec_params(
            "INSERT INTO withdrawn_codes (salt, code_hash, withdrawn_utc) VALUES "
            "($1, $2, $3) ON CONFLICT DO NOTHING",
            c.text(0), c.text(1), c.text(2));
    for (const std::string& uuid : uuids) {
        const pqxx::result gone = tx.exec_params(
            "DELETE FROM sessions WHERE uuid = $1 RETURNING participant_id", uuid);
        for (const pqxx::row& r : gone) {
            const int64_t participant = r[0].as<int64_t>();
            if (!tx.exec_params("SELECT 1 FROM sessions WHERE participant_id = $1",
                                participant)
                     .empty())
                continue;
            tx.exec_params(
                "INSERT INTO retired_participant_numbers (number) SELECT number FROM "
                "participants WHERE id = $1 ON CONFLICT DO NOTHING",
                participant);
            tx.exec_params("DELETE FROM participants WHERE id = $1", participant);
        }
    }
}

// A code the server holds must keep its name: a rename would split a server
// participant.
void refuse_renamed_server_codes(Database& m, const std::string& uri) {
    Statement renamed = m.prepare(
        "SELECT p.code FROM srv.participants p WHERE p.code NOT IN "
        "(SELECT code FROM main.participants) AND EXISTS (SELECT 1 FROM srv.sessions "
        "s "
        "WHERE s.participant_id = p.id AND s.uuid IN (SELECT uuid FROM "
        "main.sessions))");
    if (renamed.step())
        throw StoreError("refusing to merge into " + uri + ": participant code " +
                         renamed.text(0) +
                         " on the server is several people once the inputs are added "
                         "(another machine, or another file's completed session); merge "
                         "into a file instead");
}

// The merged file's sessions the server lacks (temp.new_sessions), and those it holds
// that a file's copy extends (temp.extended, with their new segments and newly answered
// trials).
void classify_sessions(Database& m) {
    m.exec(
        "CREATE TEMP TABLE new_sessions AS SELECT id FROM main.sessions "
        "WHERE uuid NOT IN (SELECT uuid FROM srv.sessions)");
    // Sessions the server holds that a file's copy extends (more answers, a later
    // status).
    m.exec(
        "CREATE TEMP TABLE extended AS SELECT m.id, m.uuid FROM main.sessions m "
        "JOIN srv.sessions s ON s.uuid = m.uuid WHERE m.status <> s.status "
        "OR (SELECT count(*) FROM main.responses WHERE session_id = m.id) <> "
        "(SELECT count(*) FROM srv.responses WHERE session_id = s.id) "
        "OR (SELECT count(*) FROM main.session_segments WHERE session_id = m.id) <> "
        "(SELECT count(*) FROM srv.session_segments WHERE session_id = s.id) "
        "OR (SELECT count(*) FROM main.trials WHERE session_id = m.id AND skipped = 1) "
        "<> "
        "(SELECT count(*) FROM srv.trials WHERE session_id = s.id AND skipped = 1)");
    m.exec(
        "CREATE TEMP TABLE ext_segments AS SELECT g.id FROM main.session_segments g "
        "JOIN temp.extended e ON e.id = g.session_id WHERE NOT EXISTS (SELECT 1 FROM "
        "srv.session_segments sg JOIN srv.sessions ss ON ss.id = sg.session_id "
        "WHERE ss.uuid = e.uuid AND sg.segment = g.segment)");
    m.exec(
        "CREATE TEMP TABLE ext_trials AS SELECT t.id FROM main.trials t "
        "JOIN temp.extended e ON e.id = t.session_id "
        "WHERE EXISTS (SELECT 1 FROM main.responses r WHERE r.trial_id = t.id) "
        "AND NOT EXISTS (SELECT 1 FROM srv.responses r JOIN srv.trials st ON st.id = "
        "r.trial_id "
        "JOIN srv.sessions ss ON ss.id = st.session_id WHERE ss.uuid = e.uuid "
        "AND st.position = t.position)");
}

// Sessions the server holds that a withdrawal in an input covers: the merge left
// them out, and the server drops them too.
std::vector<std::string> sessions_withdrawn_on_server(Database& m) {
    std::vector<std::string> withdrawn_on_server;
    Statement w = m.prepare(
        "SELECT uuid FROM srv.sessions WHERE uuid NOT IN "
        "(SELECT uuid FROM main.sessions) ORDER BY id");
    while (w.step()) withdrawn_on_server.push_back(w.text(0));
    return withdrawn_on_server;
}

// What the merge adds to the server, as reported before anything is stored.
MergeReport report_of(Database& m, const MergeReport& merged,
                      const std::vector<std::string>& files,
                      const std::vector<std::string>& withdrawn_on_server) {
    MergeReport report;
    report.notes = merged.notes;
    report.sessions_added =
        static_cast<int>(m.scalar_int("SELECT count(*) FROM temp.new_sessions"));
    report.sessions_extended =
        static_cast<int>(m.scalar_int("SELECT count(*) FROM temp.extended"));
    report.sessions_withdrawn = merged.sessions_withdrawn;
    int offered = 0;  // the files' copies of sessions the merge kept
    for (const std::string& f : files) {
        Database in(f, SQLITE_OPEN_READONLY);
        if (!in.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = 'sessions'"))
            continue;
        Statement uuids = in.prepare("SELECT uuid FROM sessions");
        Statement kept = m.prepare("SELECT count(*) FROM main.sessions WHERE uuid = ?");
        while (uuids.step()) {
            kept.reset();
            kept.bind(1, uuids.text(0));
            if (kept.step() && kept.integer(0) > 0) ++offered;
        }
    }
    report.sessions_already_present =
        std::max(0, offered - report.sessions_added - report.sessions_extended);
    if (!withdrawn_on_server.empty())
        report.notes.push_back(
            std::to_string(withdrawn_on_server.size()) + " session" +
            (withdrawn_on_server.size() == 1 ? "" : "s") +
            " of withdrawn participants removed from the server (withdrawn in an input)");
    return report;
}

// The server's ids of the merged file's studies and stimuli.

// The study and its stimuli on the server: looked up when the server holds the study
// (with the stimulus values it has not recorded yet), copied otherwise.
StudyIds study_on_server(pqxx::work& tx, Database& m) {
    StudyIds study;
    IdMap& studies = study.studies;
    IdMap& stimuli = study.stimuli;
    const bool server_has_study = m.scalar_int("SELECT count(*) FROM srv.studies") > 0;
    if (server_has_study) {
        Statement s = m.prepare("SELECT id, protocol_hash FROM main.studies");
        while (s.step())
            studies[s.integer(0)] =
                tx.exec_params1("SELECT id FROM studies WHERE protocol_hash = $1",
                                s.text(1))[0]
                    .as<int64_t>();
        Statement st = m.prepare("SELECT id, study_id, stimulus_key FROM main.stimuli");
        while (st.step())
            stimuli[st.integer(0)] = tx.exec_params1(
                                           "SELECT id FROM stimuli WHERE study_id = $1 "
                                           "AND stimulus_key = $2",
                                           studies.at(st.integer(1)), st.text(2))[0]
                                         .as<int64_t>();
        // Values the server has not recorded yet (the merge checked they agree).
        Statement first = m.prepare(
            "SELECT id, resolved_mesh, mesh_hash FROM main.stimuli WHERE "
            "resolved_mesh IS NOT "
            "NULL AND stimulus_key IN (SELECT stimulus_key FROM srv.stimuli WHERE "
            "resolved_mesh IS NULL)");
        std::string ids;
        while (first.step()) {
            tx.exec_params(
                "UPDATE stimuli SET resolved_mesh = $1, mesh_hash = $2 WHERE id = $3 "
                "AND resolved_mesh IS NULL",
                first.text(1),
                first.is_null(2) ? std::optional<std::string>() : first.text(2),
                stimuli.at(first.integer(0)));
            ids += (ids.empty() ? "" : ",") + std::to_string(first.integer(0));
        }
        if (!ids.empty())
            copy_rows(tx, m, "stimulus_values", "stimulus_id IN (" + ids + ")",
                      {{"stimulus_id", &stimuli}}, false);
    } else {
        studies = copy_rows(tx, m, "studies", "1", {}, true);
        stimuli = copy_rows(tx, m, "stimuli", "1", {{"study_id", &studies}}, true);
        copy_rows(tx, m, "stimulus_parameters", "1", {{"stimulus_id", &stimuli}}, false);
        copy_rows(tx, m, "stimulus_values", "1", {{"stimulus_id", &stimuli}}, false);
    }
    return study;
}

// The server's ids of the merged file's participants: those the server knows by code,
// the others added.
IdMap participants_on_server(pqxx::work& tx, Database& m, const IdMap& studies) {
    IdMap participants;
    Statement known = m.prepare(
        "SELECT id, code FROM main.participants WHERE code IN "
        "(SELECT code FROM srv.participants)");
    while (known.step())
        participants[known.integer(0)] =
            tx.exec_params1("SELECT id FROM participants WHERE code = $1",
                            known.text(1))[0]
                .as<int64_t>();
    const IdMap added = copy_rows(tx, m, "participants",
                                  "code NOT IN (SELECT code FROM srv.participants)",
                                  {{"study_id", &studies}}, true);
    participants.insert(added.begin(), added.end());
    return participants;
}

// The sessions the server lacks (temp.new_sessions), with their segments, trials and
// responses.
void copy_new_sessions(pqxx::work& tx, Database& m, const StudyIds& study,
                       const IdMap& participants) {
    const IdMap& studies = study.studies;
    const IdMap& stimuli = study.stimuli;
    const IdMap sessions =
        copy_rows(tx, m, "sessions", "id IN (SELECT id FROM temp.new_sessions)",
                  {{"study_id", &studies}, {"participant_id", &participants}}, true);
    const IdMap segments = copy_rows(tx, m, "session_segments",
                                     "session_id IN (SELECT id FROM temp.new_sessions)",
                                     {{"session_id", &sessions}}, true);
    copy_rows(
        tx, m, "segment_stimuli",
        "segment_id IN (SELECT g.id FROM session_segments g JOIN temp.new_sessions n "
        "ON n.id = g.session_id)",
        {{"segment_id", &segments}, {"stimulus_id", &stimuli}}, false);
    copy_series_pictures(tx, m, studies,
                         "g.session_id IN (SELECT id FROM temp.new_sessions)");
    const IdMap trials = copy_rows(
        tx, m, "trials", "session_id IN (SELECT id FROM temp.new_sessions)",
        {{"session_id", &sessions}, {"stimulus_id", &stimuli}, {"segment_id", &segments}},
        true);
    copy_rows(tx, m, "responses", "session_id IN (SELECT id FROM temp.new_sessions)",
              {{"session_id", &sessions}, {"trial_id", &trials}}, false);
    copy_rows(tx, m, "adjustments",
              "trial_id IN (SELECT t.id FROM trials t JOIN temp.new_sessions n ON n.id = "
              "t.session_id)",
              {{"trial_id", &trials}}, false);
}

// Everything the merged file adds, onto the server in one transaction: stored whole or
// not at all.
void store_on_server(Database& m, const std::string& uri,
                     const std::vector<std::string>& withdrawn_on_server) {
    try {
        pqxx::connection c(checked_server_uri(uri));
        pqxx::work tx(c);
        // The same locks stations take: no study row or participant number is created
        // meanwhile.
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", 0x4C55, 1);
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", 0x4C55, 2);
        const StudyIds study = study_on_server(tx, m);
        const IdMap participants = participants_on_server(tx, m, study.studies);
        copy_rows(tx, m, "retired_participant_numbers", "1", {}, false,
                  " ON CONFLICT DO NOTHING");
        copy_new_sessions(tx, m, study, participants);
        extend_server_sessions(tx, m, study);
        withdraw_on_server(tx, m, withdrawn_on_server);
        tx.commit();
    } catch (const StoreError&) {
        throw;
    } catch (const std::exception& e) {
        std::string why = e.what();
        throw StoreError(uri + ": merge not stored (nothing changed): " +
                         why.substr(0, why.find('\n')));
    }
}

}  // namespace

MergeReport merge_into_server(const std::vector<std::string>& files,
                              const std::string& uri,
                              const std::vector<std::string>& names) {
    namespace fs = std::filesystem;
    if (files.empty()) throw StoreError("merge: no input databases given");
    const ReadableStudyFile server_snapshot(
        uri);  // refuses an uninitialised/newer server
    std::string pattern = (fs::temp_directory_path() / "lucent-merge-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
        throw StoreError("merge: cannot create a temporary folder");
    struct Cleanup {
        std::string dir;
        ~Cleanup() {
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    } cleanup{pattern};
    const std::string merged_path = pattern + "/merged.db";
    std::vector<std::string> inputs = {server_snapshot.path()};
    inputs.insert(inputs.end(), files.begin(), files.end());
    std::vector<std::string> input_names = {uri};
    input_names.insert(input_names.end(), names.empty() ? files.begin() : names.begin(),
                       names.empty() ? files.end() : names.end());
    // The server's copy of a session and the files' are reconciled there: the kept copy
    // extends the server's or equals it (a disagreement is refused before anything).
    MergeReport merged = merge_databases(inputs, merged_path, input_names);

    Database m(merged_path, SQLITE_OPEN_READWRITE);
    m.prepare("ATTACH DATABASE ? AS srv")
        .bind(1, file_uri(server_snapshot.path(), "mode=ro"))
        .run();
    refuse_renamed_server_codes(m, uri);
    classify_sessions(m);
    const std::vector<std::string> withdrawn_on_server = sessions_withdrawn_on_server(m);
    MergeReport report = report_of(m, merged, files, withdrawn_on_server);
    store_on_server(m, uri, withdrawn_on_server);
    return report;
}

}  // namespace lucent::study
