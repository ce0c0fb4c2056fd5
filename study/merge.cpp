// Merging study databases from several lab machines: rows are matched on natural keys
// (protocol hash, stimulus key, participant code, session UUID, trial position), never
// on row ids, which differ between machines.
#include <filesystem>
#include <set>

#include "export.h"
#include "merge_provenance.h"
#include "sqlite.h"
#include "store.h"

namespace lucent::study {
namespace {

std::set<std::string> protocol_hashes(const std::string& path) {
    check_database_file(path);
    Database db(path, SQLITE_OPEN_READONLY);
    const int64_t version = db.scalar_int("PRAGMA user_version");
    if (version == 0) return {};
    if (version != kSchemaVersion)
        throw StoreError(path + ": schema " + std::to_string(version) + ", expected " +
                         std::to_string(kSchemaVersion) +
                         " (open it once with this lucent, e.g. 'lucent export', to upgrade)");
    std::set<std::string> hashes;
    Statement s = db.prepare("SELECT protocol_hash FROM studies");
    while (s.step()) hashes.insert(s.text(0));
    return hashes;
}

const char* const kCopySteps[] = {
    "INSERT OR IGNORE INTO studies (name, protocol_text, protocol_hash, created_utc) "
    "SELECT name, protocol_text, protocol_hash, created_utc FROM src.studies",

    "INSERT OR IGNORE INTO stimuli (study_id, stimulus_key, technique, mesh, image, varies) "
    "SELECT ms.id, s.stimulus_key, s.technique, s.mesh, s.image, s.varies FROM src.stimuli s "
    "JOIN src.studies ss ON ss.id = s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash",

    "INSERT OR IGNORE INTO stimulus_parameters (stimulus_id, name, value) "
    "SELECT mst.id, p.name, p.value FROM src.stimulus_parameters p "
    "JOIN src.stimuli s ON s.id = p.stimulus_id JOIN src.studies ss ON ss.id = s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "JOIN main.stimuli mst ON mst.study_id = ms.id AND mst.stimulus_key = s.stimulus_key",

    "INSERT OR IGNORE INTO participants (study_id, code, number, created_utc) "
    "SELECT ms.id, p.code, p.number, p.created_utc FROM src.participants p "
    "JOIN src.studies ss ON ss.id = p.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash",

    "CREATE TEMP TABLE new_sessions AS SELECT uuid FROM src.sessions "
    "WHERE uuid NOT IN (SELECT uuid FROM main.sessions)",

    "INSERT INTO sessions (uuid, study_id, participant_id, machine_id, seed, cell, "
    "block_order, status, started_utc, ended_utc, consent_utc, software_version, build_hash, "
    "gl_vendor, gl_renderer, display_mode, display_refresh_hz, measured_refresh_hz, "
    "refresh_note) "
    "SELECT s.uuid, ms.id, mp.id, s.machine_id, s.seed, s.cell, s.block_order, s.status, "
    "s.started_utc, s.ended_utc, s.consent_utc, s.software_version, s.build_hash, "
    "s.gl_vendor, s.gl_renderer, s.display_mode, s.display_refresh_hz, "
    "s.measured_refresh_hz, s.refresh_note FROM src.sessions s "
    "JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN src.studies ss ON ss.id = s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "JOIN src.participants sp ON sp.id = s.participant_id "
    "JOIN main.participants mp ON mp.code = sp.code ORDER BY s.id",

    "INSERT INTO trials (session_id, position, block, stimulus_id, practice, catch, catch_id, "
    "prompt, expected_rating, tolerance, break_before, onset_ns, confirm_ns, answered_utc, "
    "dropped_frames) "
    "SELECT msn.id, t.position, t.block, mst.id, t.practice, t.catch, t.catch_id, t.prompt, "
    "t.expected_rating, t.tolerance, t.break_before, t.onset_ns, t.confirm_ns, "
    "t.answered_utc, t.dropped_frames FROM src.trials t "
    "JOIN src.sessions s ON s.id = t.session_id JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN src.stimuli st ON st.id = t.stimulus_id "
    "JOIN main.stimuli mst ON mst.study_id = msn.study_id AND mst.stimulus_key = st.stimulus_key "
    "ORDER BY t.id",

    "INSERT INTO responses (session_id, trial_id, question, rating, rt_ms, changes, "
    "first_choice_ns, final_choice_ns) "
    "SELECT msn.id, mt.id, r.question, r.rating, r.rt_ms, r.changes, r.first_choice_ns, "
    "r.final_choice_ns FROM src.responses r JOIN src.trials t ON t.id = r.trial_id "
    "JOIN src.sessions s ON s.id = r.session_id JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN main.trials mt ON mt.session_id = msn.id AND mt.position = t.position ORDER BY r.id",
};

}  // namespace

MergeReport merge_databases(const std::vector<std::string>& inputs, const std::string& out_path) {
    if (inputs.empty()) throw StoreError("merge: no input databases given");
    if (std::filesystem::exists(out_path))
        throw StoreError(out_path + ": already exists; merge writes a new database");
    // Check every input before creating anything.
    std::set<std::string> first_hashes;
    std::string first_path;
    for (const std::string& in : inputs) {
        std::set<std::string> hashes = protocol_hashes(in);
        if (hashes.size() > 1)
            throw StoreError(in + ": holds " + std::to_string(hashes.size()) + " protocols");
        if (hashes.empty()) continue;
        if (first_path.empty()) {
            first_hashes = hashes;
            first_path = in;
        } else if (hashes != first_hashes) {
            throw StoreError("refusing to merge: " + in + " holds protocol " +
                             hashes.begin()->substr(0, 12) + " but " + first_path +
                             " holds protocol " + first_hashes.begin()->substr(0, 12));
        }
    }
    check_resolved_stimuli_agree(inputs);

    MergeReport report;
    Store out(out_path);
    Database& db = out.db();
    for (const std::string& in : inputs) {
        db.prepare("ATTACH DATABASE ? AS src").bind(1, file_uri(in, "mode=ro")).run();
        try {
            Transaction tx(db);
            const int64_t before = db.scalar_int("SELECT count(*) FROM main.sessions");
            const int64_t offered =
                db.scalar_int("SELECT count(*) FROM src.sqlite_schema WHERE name = 'sessions'")
                    ? db.scalar_int("SELECT count(*) FROM src.sessions")
                    : 0;
            if (offered > 0 || db.scalar_int("SELECT count(*) FROM src.sqlite_schema "
                                             "WHERE name = 'studies'") > 0) {
                for (const char* step : kCopySteps) db.exec(step);
                copy_provenance(db);
            }
            db.exec("DROP TABLE IF EXISTS temp.new_sessions");
            const int64_t added = db.scalar_int("SELECT count(*) FROM main.sessions") - before;
            tx.commit();
            report.sessions_added += static_cast<int>(added);
            report.sessions_already_present += static_cast<int>(offered - added);
        } catch (...) {
            db.exec("DETACH DATABASE src");
            throw;
        }
        db.exec("DETACH DATABASE src");
    }
    return report;
}

}  // namespace lucent::study
