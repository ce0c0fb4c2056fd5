// Merging study databases from several lab machines: rows are matched on natural keys
// (protocol hash, stimulus key, participant code and machine, session UUID, trial
// position), never on row ids, which differ between machines. A session held by several
// inputs is copied once, from the copy that extends the others (merge_reconcile.h); a
// withdrawn one not at all (withdrawal.h).
#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "common/output_file.h"
#include "study/export.h"
#include "study/merge_provenance.h"
#include "study/merge_reconcile.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/withdrawal.h"

namespace lucent::study {
namespace {

// An input as merge reads it: the file itself, or an upgraded temporary copy of an
// older schema (removed when the merge ends; the input is never written).
struct MergeInput {
    std::string path;      // as given, for messages
    std::string readable;  // what is attached: path, or the upgraded copy
    std::unique_ptr<common::PendingOutput> upgraded_copy;
    std::set<std::string> protocol_hashes;
};

MergeInput open_input(const std::string& path,
                      const std::filesystem::path& scratch_next_to,
                      std::vector<std::string>& notes) {
    check_database_file(path);  // refuses foreign, corrupt and newer databases
    MergeInput in{path, path, nullptr, {}};
    int64_t version = 0;
    {
        Database db(path, SQLITE_OPEN_READONLY);
        version = db.scalar_int("PRAGMA user_version");
        if (version > 0 && version < kSchemaVersion) {
            // Copy (VACUUM INTO reads a read-only database) and migrate the copy.
            in.upgraded_copy =
                std::make_unique<common::PendingOutput>(scratch_next_to, false);
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

// What the merge found in its inputs before writing anything: every session's copies
// and which inputs hold them, the withdrawals of every input, participants without
// sessions.
struct Survey {
    std::map<std::string, std::vector<SessionCopy>>
        copies;  // uuid -> one per input holding it
    Tombstones tombstones;
    std::set<std::string> withdrawn;               // session UUIDs the tombstones cover
    std::map<std::string, Reconciled> reconciled;  // sessions held by several inputs
    std::set<std::string> plain_codes;    // every participant code of every input
    std::set<std::string> dropped_codes;  // withdrawn participants without sessions
};

Survey survey_inputs(const std::vector<MergeInput>& inputs) {
    Survey survey;
    std::vector<std::string> names;
    for (const MergeInput& in : inputs) names.push_back(in.path);
    std::vector<std::pair<std::string, std::string>> sessionless;  // code, created_utc
    for (size_t i = 0; i < inputs.size(); ++i) {
        if (inputs[i].protocol_hashes.empty()) continue;
        Database db(inputs[i].readable, SQLITE_OPEN_READONLY);
        survey.tombstones.read(db);
        for (auto& [uuid, copy] : read_session_copies(db, static_cast<int>(i)))
            survey.copies[uuid].push_back(std::move(copy));
        Statement codes = db.prepare(
            "SELECT code, created_utc, NOT EXISTS (SELECT 1 FROM sessions s WHERE "
            "s.participant_id = p.id) FROM participants p");
        while (codes.step()) {
            survey.plain_codes.insert(codes.text(0));
            if (codes.integer(2)) sessionless.emplace_back(codes.text(0), codes.text(1));
        }
    }
    for (const auto& [code, created] : sessionless)
        if (survey.tombstones.covers("", code, "", created))
            survey.dropped_codes.insert(code);
    // Withdrawn sessions are dropped before anything is compared.
    for (const auto& [uuid, copies] : survey.copies) {
        const SessionCopy& c = copies.front();
        if (survey.tombstones.covers(uuid, c.code, c.machine_id, c.started_utc))
            survey.withdrawn.insert(uuid);
    }
    // Sessions held by several inputs: their trials and answers, then one copy each.
    for (size_t i = 0; i < inputs.size(); ++i) {
        std::map<std::string, SessionCopy*> wanted;
        for (auto& [uuid, copies] : survey.copies)
            if (copies.size() > 1 && !survey.withdrawn.count(uuid))
                for (SessionCopy& c : copies)
                    if (c.input == static_cast<int>(i)) wanted[uuid] = &c;
        if (wanted.empty()) continue;
        Database db(inputs[i].readable, SQLITE_OPEN_READONLY);
        read_session_details(db, wanted);
    }
    for (const auto& [uuid, copies] : survey.copies)
        if (copies.size() > 1 && !survey.withdrawn.count(uuid))
            survey.reconciled[uuid] = reconcile_copies(uuid, copies, names);
    return survey;
}

// The copy of `uuid` the merge keeps.
const SessionCopy& kept_copy(const Survey& survey, const std::string& uuid) {
    const auto& copies = survey.copies.at(uuid);
    const auto r = survey.reconciled.find(uuid);
    return copies[r == survey.reconciled.end() ? 0 : r->second.kept];
}

// Could one database have held all these sessions of one code? A station refuses a
// new session once the code has completed one, so not when two completed, or when one
// started after a completed one started.
bool one_file_could_hold(const std::vector<const SessionCopy*>& sessions) {
    const SessionCopy* completed = nullptr;
    for (const SessionCopy* s : sessions) {
        if (s->status != "completed") continue;
        if (completed) return false;
        completed = s;
    }
    if (!completed) return true;
    for (const SessionCopy* s : sessions)
        if (s != completed && s->started_utc > completed->started_utc) return false;
    return true;
}

// A participant is a code on one machine: lab machines all start at P01, so one code
// from several machines is several people. And on one machine, sessions of one code
// that no single file could have held together (two completed; inputs that share no
// session) are several people too. Returns session UUID -> merged code over the kept
// sessions, and a line per code kept apart.
std::map<std::string, std::string> person_codes(const Survey& survey,
                                                std::vector<std::string>& notes) {
    // (code, machine) -> its sessions; sessions are joined into one person when an input
    // holds both (union-find over the inputs holding each session).
    std::map<std::pair<std::string, std::string>, std::vector<std::string>>
        by_code_machine;
    for (const auto& [uuid, copies] : survey.copies) {
        if (survey.withdrawn.count(uuid)) continue;
        by_code_machine[{copies.front().code, copies.front().machine_id}].push_back(uuid);
    }
    struct Person {
        std::string machine, first_started, first_uuid;
        std::vector<std::string> sessions;
    };
    std::map<std::string, std::vector<Person>> people_of_code;
    for (const auto& [key, uuids] : by_code_machine) {
        std::vector<size_t> parent(uuids.size());
        for (size_t i = 0; i < parent.size(); ++i) parent[i] = i;
        auto root = [&](size_t i) {
            while (parent[i] != i) i = parent[i] = parent[parent[i]];
            return i;
        };
        std::map<int, size_t> first_of_input;
        std::vector<const SessionCopy*> kept;
        for (size_t i = 0; i < uuids.size(); ++i) {
            kept.push_back(&kept_copy(survey, uuids[i]));
            for (const SessionCopy& c : survey.copies.at(uuids[i])) {
                const auto [it, is_new] = first_of_input.try_emplace(c.input, i);
                if (!is_new) parent[root(i)] = root(it->second);
            }
        }
        std::map<size_t, Person> groups;
        const bool together = one_file_could_hold(kept);
        for (size_t i = 0; i < uuids.size(); ++i) {
            Person& p = groups[together ? 0 : root(i)];
            const std::string& started = kept[i]->started_utc;
            if (p.sessions.empty() ||
                std::tie(started, uuids[i]) < std::tie(p.first_started, p.first_uuid)) {
                p.first_started = started;
                p.first_uuid = uuids[i];
            }
            p.machine = key.second;
            p.sessions.push_back(uuids[i]);
        }
        for (auto& [id, person] : groups)
            people_of_code[key.first].push_back(std::move(person));
    }

    std::map<std::string, std::string> merged;
    for (auto& [code, people] : people_of_code) {
        if (people.size() == 1) {
            for (const std::string& uuid : people[0].sessions) merged[uuid] = code;
            continue;
        }
        std::map<std::string, std::vector<Person*>> by_machine;
        for (Person& p : people) by_machine[p.machine].push_back(&p);
        // Label each machine by the shortest id prefix (at least 8 characters) that
        // tells them apart.
        size_t length = 8;
        auto label = [&](const std::string& machine) {
            return machine.empty() ? std::string("unknown-machine")
                                   : machine.substr(0, length);
        };
        for (;; ++length) {
            std::set<std::string> labels;
            for (const auto& [m, ps] : by_machine) labels.insert(label(m));
            if (labels.size() == by_machine.size() || length > 64) break;
        }
        std::string line = code + ": sessions from " + std::to_string(by_machine.size()) +
                           " machines are different people, kept apart as";
        for (auto& [machine, on_machine] : by_machine) {
            // Several people on one machine: numbered by their first session's start.
            std::sort(on_machine.begin(), on_machine.end(),
                      [](const Person* a, const Person* b) {
                          return std::tie(a->first_started, a->first_uuid) <
                                 std::tie(b->first_started, b->first_uuid);
                      });
            std::string names;
            for (size_t k = 0; k < on_machine.size(); ++k) {
                std::string renamed = code + "@" + label(machine);
                if (on_machine.size() > 1) renamed += "#" + std::to_string(k + 1);
                if (survey.plain_codes.count(renamed))
                    throw StoreError("refusing to merge: participant code " + code +
                                     " would be kept apart as several people, and " +
                                     renamed + " is already another participant's code");
                for (const std::string& uuid : on_machine[k]->sessions)
                    merged[uuid] = renamed;
                names += " " + renamed;
            }
            line += names;
            if (on_machine.size() > 1)
                notes.push_back(
                    code + ": " + std::to_string(on_machine.size()) +
                    " people on machine " + label(machine) +
                    ": their sessions come from different files, and one file "
                    "cannot hold them all (a code completes once per file), so "
                    "they are kept apart as" +
                    names);
        }
        if (by_machine.size() > 1) notes.push_back(line);
    }
    return merged;
}

const char* const kCopySteps[] = {
    "INSERT OR IGNORE INTO studies (name, protocol_text, protocol_hash, created_utc) "
    "SELECT name, protocol_text, protocol_hash, created_utc FROM src.studies",

    "INSERT OR IGNORE INTO stimuli (study_id, stimulus_key, technique, mesh, image, "
    "varies) "
    "SELECT ms.id, s.stimulus_key, s.technique, s.mesh, s.image, s.varies FROM "
    "src.stimuli s "
    "JOIN src.studies ss ON ss.id = s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash",

    "INSERT OR IGNORE INTO stimulus_parameters (stimulus_id, name, value) "
    "SELECT mst.id, p.name, p.value FROM src.stimulus_parameters p "
    "JOIN src.stimuli s ON s.id = p.stimulus_id JOIN src.studies ss ON ss.id = "
    "s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "JOIN main.stimuli mst ON mst.study_id = ms.id AND mst.stimulus_key = s.stimulus_key",

    // One participant per (code, machine) of the new sessions, under its merged code.
    "INSERT OR IGNORE INTO participants (study_id, code, number, created_utc) "
    "SELECT DISTINCT ms.id, m.merged_code, p.number, p.created_utc FROM src.sessions s "
    "JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN src.participants p ON p.id = s.participant_id "
    "JOIN temp.person_map m ON m.uuid = s.uuid "
    "JOIN src.studies ss ON ss.id = p.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash",

    // Participants enrolled without a session keep their code unless it was split or
    // withdrawn.
    "INSERT OR IGNORE INTO participants (study_id, code, number, created_utc) "
    "SELECT ms.id, p.code, p.number, p.created_utc FROM src.participants p "
    "JOIN src.studies ss ON ss.id = p.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "WHERE NOT EXISTS (SELECT 1 FROM src.sessions s WHERE s.participant_id = p.id) "
    "AND p.code NOT IN (SELECT code FROM temp.person_map WHERE merged_code <> code) "
    "AND p.code NOT IN (SELECT code FROM temp.dropped_codes)",

    // Withdrawn participants' numbers are never handed out again, here either.
    "INSERT OR IGNORE INTO retired_participant_numbers (number) "
    "SELECT number FROM src.retired_participant_numbers",

    "INSERT INTO sessions (uuid, study_id, participant_id, machine_id, seed, cell, "
    "block_order, status, started_utc, ended_utc, consent_utc, software_version, "
    "build_hash, "
    "gl_vendor, gl_renderer, display_mode, display_refresh_hz, measured_refresh_hz, "
    "refresh_note) "
    "SELECT s.uuid, ms.id, mp.id, s.machine_id, s.seed, s.cell, s.block_order, s.status, "
    "s.started_utc, s.ended_utc, s.consent_utc, s.software_version, s.build_hash, "
    "s.gl_vendor, s.gl_renderer, s.display_mode, s.display_refresh_hz, "
    "s.measured_refresh_hz, s.refresh_note FROM src.sessions s "
    "JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN src.studies ss ON ss.id = s.study_id "
    "JOIN main.studies ms ON ms.protocol_hash = ss.protocol_hash "
    "JOIN temp.person_map m ON m.uuid = s.uuid "
    "JOIN main.participants mp ON mp.code = m.merged_code ORDER BY s.id",

    "INSERT INTO trials (session_id, position, block, stimulus_id, practice, catch, "
    "catch_id, "
    "prompt, expected_rating, tolerance, break_before, onset_ns, confirm_ns, "
    "answered_utc, "
    "dropped_frames, uuid, task, shown, kind, start_value, final_value, staircase, "
    "intensity, skipped) "
    "SELECT msn.id, t.position, t.block, mst.id, t.practice, t.catch, t.catch_id, "
    "t.prompt, "
    "t.expected_rating, t.tolerance, t.break_before, t.onset_ns, t.confirm_ns, "
    "t.answered_utc, t.dropped_frames, t.uuid, t.task, t.shown, t.kind, t.start_value, "
    "t.final_value, t.staircase, t.intensity, t.skipped FROM src.trials t "
    "JOIN src.sessions s ON s.id = t.session_id JOIN temp.new_sessions n ON n.uuid = "
    "s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN src.stimuli st ON st.id = t.stimulus_id "
    "JOIN main.stimuli mst ON mst.study_id = msn.study_id AND mst.stimulus_key = "
    "st.stimulus_key "
    "ORDER BY t.id",

    "INSERT INTO responses (session_id, trial_id, question, rating, rt_ms, changes, "
    "first_choice_ns, final_choice_ns) "
    "SELECT msn.id, mt.id, r.question, r.rating, r.rt_ms, r.changes, r.first_choice_ns, "
    "r.final_choice_ns FROM src.responses r JOIN src.trials t ON t.id = r.trial_id "
    "JOIN src.sessions s ON s.id = r.session_id JOIN temp.new_sessions n ON n.uuid = "
    "s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN main.trials mt ON mt.session_id = msn.id AND mt.position = t.position ORDER BY "
    "r.id",

    "INSERT INTO adjustments (trial_id, step, value, t_ns, input) "
    "SELECT mt.id, a.step, a.value, a.t_ns, a.input FROM src.adjustments a "
    "JOIN src.trials t ON t.id = a.trial_id JOIN src.sessions s ON s.id = t.session_id "
    "JOIN temp.new_sessions n ON n.uuid = s.uuid "
    "JOIN main.sessions msn ON msn.uuid = s.uuid "
    "JOIN main.trials mt ON mt.session_id = msn.id AND mt.position = t.position ORDER BY "
    "a.trial_id, a.step",
};

}  // namespace

MergeReport merge_databases(const std::vector<std::string>& inputs,
                            const std::string& out_path,
                            const std::vector<std::string>& names) {
    if (inputs.empty()) throw StoreError("merge: no input databases given");
    if (!names.empty() && names.size() != inputs.size())
        throw StoreError("merge: " + std::to_string(names.size()) + " names for " +
                         std::to_string(inputs.size()) + " inputs");
    MergeReport report;
    try {
        // A new file only, never an input or any database.
        common::check_output_file(out_path, {inputs.begin(), inputs.end()}, false, "");
    } catch (const common::OutputError& e) {
        throw StoreError(std::string(e.what()) + "; merge writes a new database");
    }
    // Check every input before creating anything.
    std::vector<MergeInput> opened;
    int first = -1;  // the first input holding a study
    for (size_t i = 0; i < inputs.size(); ++i) {
        MergeInput& in =
            opened.emplace_back(open_input(inputs[i], out_path, report.notes));
        if (!names.empty()) in.path = names[i];
        if (in.protocol_hashes.size() > 1)
            throw StoreError(in.path + ": holds " +
                             std::to_string(in.protocol_hashes.size()) + " protocols");
        if (in.protocol_hashes.empty()) continue;
        if (first < 0) {
            first = static_cast<int>(opened.size()) - 1;
        } else if (in.protocol_hashes != opened[first].protocol_hashes) {
            throw StoreError("refusing to merge: " + in.path + " holds protocol " +
                             in.protocol_hashes.begin()->substr(0, 12) + " but " +
                             opened[first].path + " holds protocol " +
                             opened[first].protocol_hashes.begin()->substr(0, 12));
        }
    }
    {
        // Inputs upgraded from before schema 3 recorded no resolved values: nothing to
        // compare.
        std::vector<std::string> current;
        for (size_t i = 0; i < opened.size(); ++i)
            if (!opened[i].upgraded_copy) current.push_back(inputs[i]);
        check_resolved_stimuli_agree(current);
    }
    // Every copy of every session, and every withdrawal, before anything is written: a
    // withdrawal in the last input drops the session from the first, and the copy kept
    // does not depend on the order of the inputs.
    const Survey survey = survey_inputs(opened);
    const auto people = person_codes(survey, report.notes);
    std::map<int, std::vector<std::string>>
        kept_from;  // input -> sessions copied from it
    for (const auto& [uuid, copies] : survey.copies)
        if (!survey.withdrawn.count(uuid))
            kept_from[kept_copy(survey, uuid).input].push_back(uuid);
    report.sessions_withdrawn = static_cast<int>(survey.withdrawn.size());
    for (const auto& [uuid, r] : survey.reconciled) {
        report.sessions_already_present += r.identical;
        if (r.extended > 0) ++report.sessions_extended;
    }

    // Written under a temporary name and renamed when complete: nobody sees half a merge.
    common::PendingOutput pending(out_path, false);
    {
        Store out(pending.temporary().string());
        Database& db = out.db();
        db.exec(
            "CREATE TEMP TABLE person_map (uuid TEXT PRIMARY KEY, code TEXT NOT NULL, "
            "merged_code TEXT NOT NULL)");
        Statement map = db.prepare("INSERT INTO temp.person_map VALUES (?, ?, ?)");
        for (const auto& [uuid, merged_code] : people) {
            map.reset();
            map.bind(1, uuid)
                .bind(2, survey.copies.at(uuid).front().code)
                .bind(3, merged_code)
                .run();
        }
        db.exec("CREATE TEMP TABLE dropped_codes (code TEXT PRIMARY KEY)");
        Statement dropped = db.prepare("INSERT INTO temp.dropped_codes VALUES (?)");
        for (const std::string& code : survey.dropped_codes) {
            dropped.reset();
            dropped.bind(1, code).run();
        }
        for (size_t i = 0; i < opened.size(); ++i) {
            const MergeInput& in = opened[i];
            db.prepare("ATTACH DATABASE ? AS src")
                .bind(1, file_uri(in.readable, "mode=ro"))
                .run();
            try {
                Transaction tx(db);
                const int64_t before =
                    db.scalar_int("SELECT count(*) FROM main.sessions");
                if (db.scalar_int(
                        "SELECT count(*) FROM src.sqlite_schema WHERE name = 'studies'") >
                    0) {
                    db.exec("CREATE TEMP TABLE new_sessions (uuid TEXT PRIMARY KEY)");
                    Statement add =
                        db.prepare("INSERT INTO temp.new_sessions VALUES (?)");
                    for (const std::string& uuid : kept_from[static_cast<int>(i)]) {
                        add.reset();
                        add.bind(1, uuid).run();
                    }
                    for (const char* step : kCopySteps) db.exec(step);
                    copy_provenance(db);
                }
                db.exec("DROP TABLE IF EXISTS temp.new_sessions");
                const int64_t added =
                    db.scalar_int("SELECT count(*) FROM main.sessions") - before;
                tx.commit();
                report.sessions_added += static_cast<int>(added);
            } catch (...) {
                db.exec("DETACH DATABASE src");
                throw;
            }
            db.exec("DETACH DATABASE src");
        }
        // The withdrawals travel on: a later merge of this file drops them too.
        Transaction tx(db);
        survey.tombstones.write(db);
        tx.commit();
    }
    try {
        pending.commit();
    } catch (const common::OutputError& e) {
        throw StoreError(e.what());
    }
    return report;
}

}  // namespace lucent::study
