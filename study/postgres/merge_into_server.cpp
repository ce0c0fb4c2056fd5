// Station files into a study server (merge_into_server.h).
#include "postgres/merge_into_server.h"

#include <pqxx/pqxx>

#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "postgres/postgres_store.h"
#include "sqlite.h"
#include "store.h"
#include "study_store.h"

namespace lucent::study {
namespace {

using IdMap = std::map<int64_t, int64_t>;  // row id in the merged file -> on the server

std::vector<std::string> columns_of(Database& m, const std::string& table) {
    std::vector<std::string> out;
    Statement s = m.prepare("SELECT name FROM pragma_table_info(?) WHERE name <> 'id'");
    s.bind(1, table);
    while (s.step()) out.push_back(s.text(0));
    return out;
}

// Inserts the rows of `table` in the merged file `m` that `where` selects, with each
// column in `remap` translated to the server's ids. Table, column and condition texts are
// this file's constants; every value travels as a parameter. Returns the id map when
// the table has an id column.
IdMap copy_rows(pqxx::work& tx, Database& m, const std::string& table, const std::string& where,
                const std::map<std::string, const IdMap*>& remap, bool has_id,
                const std::string& conflict = "") {
    const std::vector<std::string> columns = columns_of(m, table);
    std::string names, marks;
    for (size_t c = 0; c < columns.size(); ++c) {
        names += (c ? ", " : "") + columns[c];
        marks += (c ? ", $" : "$") + std::to_string(c + 1);
    }
    const std::string insert = "INSERT INTO " + table + " (" + names + ") VALUES (" + marks +
                               ")" + conflict + (has_id ? " RETURNING id" : "");
    Statement rows = m.prepare("SELECT " + std::string(has_id ? "id, " : "0, ") + names + " FROM " +
                               table + " WHERE " + where + " ORDER BY 1");
    IdMap ids;
    while (rows.step()) {
        std::vector<std::optional<std::string>> values;
        for (size_t c = 0; c < columns.size(); ++c) {
            const int col = static_cast<int>(c) + 1;
            if (rows.is_null(col)) {
                values.emplace_back();
                continue;
            }
            const auto mapped = remap.find(columns[c]);
            if (mapped == remap.end()) {
                values.emplace_back(rows.text(col));
                continue;
            }
            const auto id = mapped->second->find(rows.integer(col));
            if (id == mapped->second->end())
                throw StoreError("merge: " + table + "." + columns[c] + " " +
                                 std::to_string(rows.integer(col)) + " has no row on the server");
            values.emplace_back(std::to_string(id->second));
        }
        const pqxx::result r = tx.exec_params(insert, pqxx::prepare::make_dynamic_params(values));
        if (has_id) ids[rows.integer(0)] = r[0][0].as<int64_t>();
    }
    return ids;
}

}  // namespace

MergeReport merge_into_server(const std::vector<std::string>& files, const std::string& uri) {
    namespace fs = std::filesystem;
    if (files.empty()) throw StoreError("merge: no input databases given");
    const ReadableStudyFile server_snapshot(uri);  // refuses an uninitialised/newer server
    std::string pattern = (fs::temp_directory_path() / "lucent-merge-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw StoreError("merge: cannot create a temporary folder");
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
    MergeReport merged = merge_databases(inputs, merged_path);

    Database m(merged_path, SQLITE_OPEN_READWRITE);
    m.prepare("ATTACH DATABASE ? AS srv").bind(1, file_uri(server_snapshot.path(), "mode=ro")).run();
    // A code the server holds must keep its name: a rename would split a server participant.
    {
        Statement renamed = m.prepare(
            "SELECT code FROM srv.participants WHERE code NOT IN (SELECT code FROM main.participants)");
        if (renamed.step())
            throw StoreError("refusing to merge into " + uri + ": participant code " +
                             renamed.text(0) +
                             " on the server also comes from another machine in the inputs; "
                             "merge into a file instead");
    }
    m.exec("CREATE TEMP TABLE new_sessions AS SELECT id FROM main.sessions "
           "WHERE uuid NOT IN (SELECT uuid FROM srv.sessions)");
    MergeReport report;
    report.notes = merged.notes;
    report.sessions_added = static_cast<int>(m.scalar_int("SELECT count(*) FROM temp.new_sessions"));
    int offered = 0;
    for (const std::string& f : files) {
        Database in(f, SQLITE_OPEN_READONLY);
        if (in.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = 'sessions'"))
            offered += static_cast<int>(in.scalar_int("SELECT count(*) FROM sessions"));
    }
    report.sessions_already_present = offered - report.sessions_added;

    try {
        pqxx::connection c(checked_server_uri(uri));
        pqxx::work tx(c);
        // The same locks stations take: no study row or participant number is created
        // meanwhile.
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", 0x4C55, 1);
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", 0x4C55, 2);
        IdMap studies, stimuli, participants, sessions, segments, trials;
        const bool server_has_study = m.scalar_int("SELECT count(*) FROM srv.studies") > 0;
        if (server_has_study) {
            Statement s = m.prepare("SELECT id, protocol_hash FROM main.studies");
            while (s.step())
                studies[s.integer(0)] = tx.exec_params1("SELECT id FROM studies WHERE protocol_hash = $1",
                                                        s.text(1))[0]
                                            .as<int64_t>();
            Statement st = m.prepare("SELECT id, study_id, stimulus_key FROM main.stimuli");
            while (st.step())
                stimuli[st.integer(0)] = tx.exec_params1("SELECT id FROM stimuli WHERE study_id = $1 "
                                                         "AND stimulus_key = $2",
                                                         studies.at(st.integer(1)), st.text(2))[0]
                                             .as<int64_t>();
            // Values the server has not recorded yet (the merge checked they agree).
            Statement first = m.prepare(
                "SELECT id, resolved_mesh, mesh_hash FROM main.stimuli WHERE resolved_mesh IS NOT "
                "NULL AND stimulus_key IN (SELECT stimulus_key FROM srv.stimuli WHERE "
                "resolved_mesh IS NULL)");
            std::string ids;
            while (first.step()) {
                tx.exec_params("UPDATE stimuli SET resolved_mesh = $1, mesh_hash = $2 WHERE id = $3 "
                               "AND resolved_mesh IS NULL",
                               first.text(1), first.is_null(2) ? std::optional<std::string>() : first.text(2),
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
        {
            Statement known = m.prepare("SELECT id, code FROM main.participants WHERE code IN "
                                        "(SELECT code FROM srv.participants)");
            while (known.step())
                participants[known.integer(0)] =
                    tx.exec_params1("SELECT id FROM participants WHERE code = $1", known.text(1))[0]
                        .as<int64_t>();
            const IdMap added = copy_rows(tx, m, "participants",
                                          "code NOT IN (SELECT code FROM srv.participants)",
                                          {{"study_id", &studies}}, true);
            participants.insert(added.begin(), added.end());
        }
        copy_rows(tx, m, "retired_participant_numbers", "1", {}, false, " ON CONFLICT DO NOTHING");
        sessions = copy_rows(tx, m, "sessions", "id IN (SELECT id FROM temp.new_sessions)",
                             {{"study_id", &studies}, {"participant_id", &participants}}, true);
        segments = copy_rows(tx, m, "session_segments",
                             "session_id IN (SELECT id FROM temp.new_sessions)",
                             {{"session_id", &sessions}}, true);
        copy_rows(tx, m, "segment_stimuli",
                  "segment_id IN (SELECT g.id FROM session_segments g JOIN temp.new_sessions n "
                  "ON n.id = g.session_id)",
                  {{"segment_id", &segments}, {"stimulus_id", &stimuli}}, false);
        trials = copy_rows(tx, m, "trials", "session_id IN (SELECT id FROM temp.new_sessions)",
                           {{"session_id", &sessions}, {"stimulus_id", &stimuli},
                            {"segment_id", &segments}},
                           true);
        copy_rows(tx, m, "responses", "session_id IN (SELECT id FROM temp.new_sessions)",
                  {{"session_id", &sessions}, {"trial_id", &trials}}, false);
        tx.commit();
    } catch (const StoreError&) {
        throw;
    } catch (const std::exception& e) {
        std::string why = e.what();
        throw StoreError(uri + ": merge not stored (nothing changed): " + why.substr(0, why.find('\n')));
    }
    return report;
}

}  // namespace lucent::study
