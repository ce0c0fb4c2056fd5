// Merging study databases from several lab machines: rows are matched on natural keys
// (protocol hash, stimulus key, participant code and machine, session UUID, trial
// position), never on row ids, which differ between machines.
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "export.h"
#include "merge_provenance.h"
#include "output_file.h"
#include "sqlite.h"
#include "store.h"

namespace lucent::study {
namespace {

// An input as merge reads it: the file itself, or an upgraded temporary copy of an
// older schema (removed when the merge ends; the input is never written).
struct MergeInput {
    std::string path;     // as given, for messages
    std::string readable; // what is attached: path, or the upgraded copy
    std::unique_ptr<output::PendingOutput> upgraded_copy;
    std::set<std::string> protocol_hashes;
};

MergeInput open_input(const std::string& path, const std::filesystem::path& scratch_next_to,
                      std::vector<std::string>& notes) {
    check_database_file(path);  // refuses foreign, corrupt and newer databases
    MergeInput in{path, path, nullptr, {}};
    int64_t version = 0;
    {
        Database db(path, SQLITE_OPEN_READONLY);
        version = db.scalar_int("PRAGMA user_version");
        if (version > 0 && version < kSchemaVersion) {
            // Copy (VACUUM INTO reads a read-only database) and migrate the copy.
            in.upgraded_copy = std::make_unique<output::PendingOutput>(scratch_next_to, false);
            in.readable = in.upgraded_copy->temporary().string();
            db.prepare("VACUUM INTO ?").bind(1, in.readable).run();
        }
    }
    if (in.upgraded_copy) {
        Database copy(in.readable, SQLITE_OPEN_READWRITE);
        migrate(copy);
        notes.push_back(path + ": schema " + std::to_string(version) +
                        ", read through an upgraded copy (the file is unchanged)");
    }
    if (version == 0) return in;
    Database db(in.readable, SQLITE_OPEN_READONLY);
    Statement s = db.prepare("SELECT protocol_hash FROM studies");
    while (s.step()) in.protocol_hashes.insert(s.text(0));
    return in;
}

// A participant is a code on one machine: lab machines all start at P01, so one code
// from several machines is several people. Returns (code, machine_id) -> merged code,
// over each session's first copy (sessions are de-duplicated by UUID), and a line per
// code kept apart.
std::map<std::pair<std::string, std::string>, std::string> person_codes(
    const std::vector<MergeInput>& inputs, std::vector<std::string>& notes) {
    std::map<std::string, std::set<std::string>> machines_of_code;
    std::set<std::string> seen_sessions, plain_codes;
    for (const MergeInput& in : inputs) {
        if (in.protocol_hashes.empty()) continue;
        Database db(in.readable, SQLITE_OPEN_READONLY);
        Statement s = db.prepare(
            "SELECT se.uuid, p.code, se.machine_id FROM sessions se "
            "JOIN participants p ON p.id = se.participant_id ORDER BY se.id");
        while (s.step())
            if (seen_sessions.insert(s.text(0)).second) machines_of_code[s.text(1)].insert(s.text(2));
        Statement codes = db.prepare("SELECT code FROM participants");
        while (codes.step()) plain_codes.insert(codes.text(0));
    }
    std::map<std::pair<std::string, std::string>, std::string> merged;
    for (const auto& [code, machines] : machines_of_code) {
        if (machines.size() == 1) {
            merged[{code, *machines.begin()}] = code;
            continue;
        }
        // Label each machine by the shortest id prefix (at least 8 characters) that
        // tells them apart.
        size_t length = 8;
        auto label = [&](const std::string& machine) {
            return machine.empty() ? std::string("unknown-machine") : machine.substr(0, length);
        };
        for (;; ++length) {
            std::set<std::string> labels;
            for (const std::string& m : machines) labels.insert(label(m));
            if (labels.size() == machines.size() || length > 64) break;
        }
        std::string line = code + ": sessions from " + std::to_string(machines.size()) +
                           " machines are different people, kept apart as";
        for (const std::string& m : machines) {
            const std::string renamed = code + "@" + label(m);
            if (plain_codes.count(renamed))
                throw StoreError("refusing to merge: participant code " + code +
                                 " comes from several machines, and " + renamed +
                                 " is already another participant's code");
            merged[{code, m}] = renamed;
            line += " " + renamed;
        }
        notes.push_back(line);
    }
    return merged;
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

    "CREATE TEMP TABLE new_sessions AS SELECT uuid FROM src.sessions "
    "WHERE uuid NOT IN (SELECT uuid FROM main.sessions)",

    // One participant per (code, machine) of the new sessions, under its merged code.
    "INSERT OR IGNORE INTO participants (study_id, code, number, created_utc) "
    "SELECT DISTINCT ms.id, m.merged_code, p.number, p.created_utc FROM src.sessions s "
    "JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN src.participants p ON p.id = s.participant_id "
    "JOIN temp.person_map m ON m.code = p.code AND m.machine_id = s.machine_id "
    "JOIN src.studies ss ON ss.id = p.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash",

    // Participants enrolled without a session keep their code unless it was split.
    "INSERT OR IGNORE INTO participants (study_id, code, number, created_utc) "
    "SELECT ms.id, p.code, p.number, p.created_utc FROM src.participants p "
    "JOIN src.studies ss ON ss.id = p.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "WHERE NOT EXISTS (SELECT 1 FROM src.sessions s WHERE s.participant_id = p.id) "
    "AND p.code NOT IN (SELECT code FROM temp.person_map WHERE merged_code <> code)",

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
    "JOIN temp.person_map m ON m.code = sp.code AND m.machine_id = s.machine_id "
    "JOIN main.participants mp ON mp.code = m.merged_code ORDER BY s.id",

    "INSERT INTO trials (session_id, position, block, stimulus_id, practice, catch, catch_id, "
    "prompt, expected_rating, tolerance, break_before, onset_ns, confirm_ns, answered_utc, "
    "dropped_frames, uuid) "
    "SELECT msn.id, t.position, t.block, mst.id, t.practice, t.catch, t.catch_id, t.prompt, "
    "t.expected_rating, t.tolerance, t.break_before, t.onset_ns, t.confirm_ns, "
    "t.answered_utc, t.dropped_frames, t.uuid FROM src.trials t "
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
    MergeReport report;
    try {
        // A new file only, never an input or any database.
        output::check_output_file(out_path, {inputs.begin(), inputs.end()}, false, "");
    } catch (const output::OutputError& e) {
        throw StoreError(std::string(e.what()) + "; merge writes a new database");
    }
    // Check every input before creating anything.
    std::vector<MergeInput> opened;
    int first = -1;  // the first input holding a study
    for (const std::string& path : inputs) {
        const MergeInput& in = opened.emplace_back(open_input(path, out_path, report.notes));
        if (in.protocol_hashes.size() > 1)
            throw StoreError(path + ": holds " + std::to_string(in.protocol_hashes.size()) +
                             " protocols");
        if (in.protocol_hashes.empty()) continue;
        if (first < 0) {
            first = static_cast<int>(opened.size()) - 1;
        } else if (in.protocol_hashes != opened[first].protocol_hashes) {
            throw StoreError("refusing to merge: " + path + " holds protocol " +
                             in.protocol_hashes.begin()->substr(0, 12) + " but " +
                             opened[first].path + " holds protocol " +
                             opened[first].protocol_hashes.begin()->substr(0, 12));
        }
    }
    {
        // Inputs upgraded from before schema 3 recorded no resolved values: nothing to compare.
        std::vector<std::string> current;
        for (const MergeInput& in : opened)
            if (!in.upgraded_copy) current.push_back(in.path);
        check_resolved_stimuli_agree(current);
    }
    const auto people = person_codes(opened, report.notes);

    // Written under a temporary name and renamed when complete: nobody sees half a merge.
    output::PendingOutput pending(out_path, false);
    {
        Store out(pending.temporary().string());
        Database& db = out.db();
        db.exec("CREATE TEMP TABLE person_map (code TEXT NOT NULL, machine_id TEXT NOT NULL, "
                "merged_code TEXT NOT NULL, PRIMARY KEY (code, machine_id))");
        Statement map = db.prepare("INSERT INTO temp.person_map VALUES (?, ?, ?)");
        for (const auto& [key, merged_code] : people) {
            map.reset();
            map.bind(1, key.first).bind(2, key.second).bind(3, merged_code).run();
        }
        for (const MergeInput& in : opened) {
            db.prepare("ATTACH DATABASE ? AS src").bind(1, file_uri(in.readable, "mode=ro")).run();
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
    }
    try {
        pending.commit();
    } catch (const output::OutputError& e) {
        throw StoreError(e.what());
    }
    return report;
}

}  // namespace lucent::study
