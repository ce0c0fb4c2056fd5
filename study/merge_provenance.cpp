// Provenance in merges: stimuli must agree value for value; segments travel with their
// sessions (matched by session UUID and segment number, never by row id).
#include "study/merge_provenance.h"

#include <map>

#include "study/sqlite/sqlite_store.h"

namespace lucent::study {
namespace {

const char* const kProvenanceCopySteps[] = {
    "UPDATE main.stimuli SET "
    "resolved_mesh = (SELECT s.resolved_mesh FROM src.stimuli s "
    "JOIN src.studies ss ON ss.id = s.study_id JOIN main.studies ms "
    "ON ms.protocol_hash = ss.protocol_hash WHERE ms.id = main.stimuli.study_id "
    "AND s.stimulus_key = main.stimuli.stimulus_key), "
    "mesh_hash = (SELECT s.mesh_hash FROM src.stimuli s "
    "JOIN src.studies ss ON ss.id = s.study_id JOIN main.studies ms "
    "ON ms.protocol_hash = ss.protocol_hash WHERE ms.id = main.stimuli.study_id "
    "AND s.stimulus_key = main.stimuli.stimulus_key) "
    "WHERE resolved_mesh IS NULL",

    // Values agree where both have them (checked first), so IGNORE only skips equal rows.
    "INSERT OR IGNORE INTO stimulus_values (stimulus_id, name, value) "
    "SELECT mst.id, v.name, v.value FROM src.stimulus_values v "
    "JOIN src.stimuli s ON s.id = v.stimulus_id JOIN src.studies ss ON ss.id = "
    "s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "JOIN main.stimuli mst ON mst.study_id = ms.id AND mst.stimulus_key = s.stimulus_key",

    "INSERT INTO session_segments (session_id, segment, started_utc, machine_id, "
    "software_version, build_hash, gl_vendor, gl_renderer, display_mode, "
    "display_refresh_hz, measured_refresh_hz, refresh_note, stimulus_source, series_set) "
    "SELECT msn.id, g.segment, g.started_utc, g.machine_id, g.software_version, "
    "g.build_hash, g.gl_vendor, g.gl_renderer, g.display_mode, g.display_refresh_hz, "
    "g.measured_refresh_hz, g.refresh_note, g.stimulus_source, g.series_set FROM "
    "src.session_segments "
    "g "
    "JOIN src.sessions s ON s.id = g.session_id JOIN temp.new_sessions n ON n.uuid = "
    "s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid ORDER BY g.id",

    "INSERT INTO segment_stimuli (segment_id, stimulus_id, source, file, content_hash, "
    "software_version, build_hash) "
    "SELECT mg.id, mst.id, x.source, x.file, x.content_hash, x.software_version, "
    "x.build_hash FROM src.segment_stimuli x "
    "JOIN src.session_segments g ON g.id = x.segment_id "
    "JOIN src.sessions s ON s.id = g.session_id JOIN temp.new_sessions n ON n.uuid = "
    "s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN main.session_segments mg ON mg.session_id = msn.id AND mg.segment = g.segment "
    "JOIN src.stimuli st ON st.id = x.stimulus_id "
    "JOIN main.stimuli mst ON mst.study_id = msn.study_id AND mst.stimulus_key = "
    "st.stimulus_key",

    // A set is its hash: the same set from two inputs is one set of rows.
    "INSERT OR IGNORE INTO series_pictures (study_id, set_hash, picture, file, "
    "content_hash, software_version, build_hash) "
    "SELECT ms.id, x.set_hash, x.picture, x.file, x.content_hash, x.software_version, "
    "x.build_hash FROM src.series_pictures x JOIN src.studies ss ON ss.id = x.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "WHERE x.set_hash IN (SELECT g.series_set FROM src.session_segments g "
    "JOIN src.sessions s ON s.id = g.session_id JOIN temp.new_sessions n ON n.uuid = "
    "s.uuid)",

    "UPDATE main.trials SET segment_id = ("
    "SELECT mg.id FROM src.trials t JOIN src.sessions s ON s.id = t.session_id "
    "JOIN src.session_segments g ON g.id = t.segment_id "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN main.session_segments mg ON mg.session_id = msn.id AND mg.segment = g.segment "
    "WHERE msn.id = main.trials.session_id AND t.position = main.trials.position) "
    "WHERE session_id IN (SELECT msn.id FROM main.sessions msn "
    "JOIN temp.new_sessions n ON n.uuid = msn.uuid)",
};

}  // namespace

void check_resolved_stimuli_agree(const std::vector<std::string>& inputs) {
    std::map<std::string, std::pair<ResolvedStimulus, std::string>>
        first;  // key -> (values, file)
    for (const std::string& path : inputs) {
        check_database_file(path);
        Database db(path, SQLITE_OPEN_READONLY);
        for (const auto& [key, resolved] : read_resolved_stimuli(db)) {
            const auto [it, is_new] = first.try_emplace(key, resolved, path);
            if (is_new) continue;
            const std::string difference = resolved_difference(
                key, it->second.first, it->second.second, resolved, path);
            if (!difference.empty())
                throw StoreError("refusing to merge: " + difference +
                                 " (the same stimulus id showed different pictures)");
        }
    }
}

void copy_provenance(Database& db) {
    for (const char* step : kProvenanceCopySteps) db.exec(step);
}

}  // namespace lucent::study
