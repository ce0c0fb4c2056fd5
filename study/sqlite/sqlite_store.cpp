// The SQLite backend: studies, participants and their claims, sessions and segments,
// trials and responses, in SQL. The schema is study/schema.cpp, the file's safety check
// and migrations database_file.cpp, the rules it keeps study/store_rules.cpp.
#include "study/sqlite/sqlite_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "study/schema.h"
#include "study/store_rules.h"
#include "study/withdrawal.h"

namespace lucent::study {
namespace {

int64_t first_int(Statement& s) { return s.step() ? s.integer(0) : 0; }

// Binds `env` to the environment columns' parameters (schema.h: kEnvironmentColumns),
// the first at index `first`.
Statement& bind_environment(Statement& s, int first, const SessionEnvironment& env) {
    return s.bind(first, env.machine_id)
        .bind(first + 1, env.software_version)
        .bind(first + 2, env.build_hash)
        .bind(first + 3, env.gl_vendor)
        .bind(first + 4, env.gl_renderer)
        .bind(first + 5, env.display_mode)
        .bind(first + 6, env.display_refresh_hz)
        .bind(first + 7, env.measured_refresh_hz)
        .bind(first + 8, env.refresh_note);
}

// Enrolment order: one past the highest number held, not the count, which falls after a
// withdrawal and would hand out a number (a Latin-square row) still in use. The caller
// holds the write lock until the number is taken.
int next_participant_number(Database& db) {
    return static_cast<int>(db.scalar_int(
               "SELECT max(coalesce((SELECT max(number) FROM participants), 0), "
               "coalesce((SELECT max(number) FROM retired_participant_numbers), 0))")) +
           1;
}

// The participant's row, enrolled now; its id.
int64_t insert_participant(Database& db, int64_t study_id, const std::string& code,
                           int number) {
    db.prepare(
          "INSERT INTO participants (study_id, code, number, created_utc) "
          "VALUES (?, ?, ?, ?)")
        .bind(1, study_id)
        .bind(2, code)
        .bind(3, number)
        .bind(4, utc_now_iso8601())
        .run();
    return db.last_insert_id();
}

}  // namespace

std::map<std::string, ResolvedStimulus> read_resolved_stimuli(Database& db) {
    std::map<std::string, ResolvedStimulus> out;
    if (db.scalar_int("PRAGMA user_version") < 3) return out;
    Statement s = db.prepare(
        "SELECT stimulus_key, technique, resolved_mesh, mesh_hash "
        "FROM stimuli WHERE resolved_mesh IS NOT NULL");
    while (s.step()) out[s.text(0)] = {s.text(1), s.text(2), s.text(3), {}};
    Statement v = db.prepare(
        "SELECT st.stimulus_key, v.name, v.value FROM stimulus_values v "
        "JOIN stimuli st ON st.id = v.stimulus_id");
    while (v.step()) out[v.text(0)].values[v.text(1)] = v.text(2);
    return out;
}

Store::Store(const std::string& path, const std::string& vfs)
    : db_((check_database_file(path), path),
          SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_URI, vfs) {
    db_.exec("PRAGMA journal_mode = WAL");
    db_.exec("PRAGMA synchronous = FULL");
    db_.exec("PRAGMA foreign_keys = ON");
    migrate(db_);
}

int64_t Store::ensure_study(const Protocol& protocol) {
    const std::string hash = protocol_hash(protocol.text);
    {
        Statement s = db_.prepare("SELECT id, protocol_hash, name FROM studies");
        while (s.step()) {
            if (s.text(1) == hash) return s.integer(0);
            throw StoreError(db_.path() + ": holds study '" + s.text(2) + "' (protocol " +
                             s.text(1).substr(0, 12) + "), not this protocol (" +
                             hash.substr(0, 12) + "); use a new database per protocol");
        }
    }
    Transaction tx(db_);
    db_.prepare(
           "INSERT INTO studies (name, protocol_text, protocol_hash, created_utc) "
           "VALUES (?, ?, ?, ?)")
        .bind(1, protocol.name)
        .bind(2, protocol.text)
        .bind(3, hash)
        .bind(4, utc_now_iso8601())
        .run();
    const int64_t study_id = db_.last_insert_id();
    Statement stim = db_.prepare(
        "INSERT INTO stimuli (study_id, stimulus_key, technique, mesh, image, varies) "
        "VALUES (?, ?, ?, ?, ?, ?)");
    Statement param = db_.prepare(
        "INSERT INTO stimulus_parameters (stimulus_id, name, value) VALUES (?, ?, ?)");
    for (const Stimulus& s : protocol.stimuli) {
        std::string varies;
        for (const std::string& v : s.varies) varies += (varies.empty() ? "" : " ") + v;
        stim.reset();
        stim.bind(1, study_id)
            .bind(2, s.id)
            .bind(3, s.technique)
            .bind(4, s.mesh)
            .bind(5, s.image)
            .bind(6, varies)
            .run();
        const int64_t stimulus_id = db_.last_insert_id();
        for (const auto& [name, value] : s.columns()) {
            param.reset();
            param.bind(1, stimulus_id).bind(2, name).bind(3, value).run();
        }
    }
    tx.commit();
    return study_id;
}

int64_t Store::ensure_participant(int64_t study_id, const std::string& code,
                                  int* number) {
    // BEGIN IMMEDIATE: the number is read and taken under one write lock, so two
    // processes on this file never take the same one.
    Transaction tx(db_);
    Statement find = db_.prepare("SELECT id, number FROM participants WHERE code = ?");
    find.bind(1, code);
    if (find.step()) {
        if (number) *number = static_cast<int>(find.integer(1));
        return find.integer(0);  // nothing written: the rollback is a no-op
    }
    int n = participant_number_from_code(code);
    if (n < 0) n = next_participant_number(db_);
    const int64_t id = insert_participant(db_, study_id, code, n);
    tx.commit();
    if (number) *number = n;
    return id;
}

SessionRow Store::create_session(int64_t study_id, int64_t participant_id,
                                 const TrialPlan& plan, uint64_t seed,
                                 const SessionEnvironment& env) {
    Transaction tx(db_);
    SessionRow row =
        insert_session(study_id, participant_id, plan, seed, env, new_uuid_v4(), "");
    tx.commit();
    return row;
}

SessionRow Store::insert_session(int64_t study_id, int64_t participant_id,
                                 const TrialPlan& plan, uint64_t seed,
                                 const SessionEnvironment& env, const std::string& uuid,
                                 const std::string& allocation) {
    SessionRow row = new_session_row(uuid, participant_id, seed, plan);
    Statement session = db_.prepare(
        "INSERT INTO sessions (uuid, study_id, participant_id, seed, cell, block_order, "
        "status, started_utc, allocation, " +
        std::string(kEnvironmentColumns) +
        ") VALUES (?, ?, ?, ?, ?, ?, 'running', ?, ?, " + environment_values(false, 1) +
        ")");
    session.bind(1, row.uuid)
        .bind(2, study_id)
        .bind(3, participant_id)
        .bind(4, std::to_string(seed))
        .bind(5, plan.cell)
        .bind(6, block_order_text(plan))
        .bind(7, utc_now_iso8601())
        .bind(8,
              allocation.empty() ? std::nullopt : std::optional<std::string>(allocation));
    bind_environment(session, 9, env).run();
    row.id = db_.last_insert_id();
    Statement code = db_.prepare("SELECT code FROM participants WHERE id = ?");
    if (code.bind(1, participant_id).step()) row.participant = code.text(0);
    insert_segment(row.id, 1, env);
    Statement insert = db_.prepare(
        "INSERT INTO trials (session_id, position, block, stimulus_id, practice, catch, "
        "catch_id, prompt, expected_rating, tolerance, break_before, uuid, task, shown, "
        "kind, start_value, staircase) "
        "VALUES (?, ?, ?, (SELECT id FROM stimuli WHERE study_id = ? AND stimulus_key = "
        "?), ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (const PlannedTrial& t : plan.trials) {
        insert.reset();
        insert.bind(1, row.id)
            .bind(2, t.position)
            .bind(3, t.block)
            .bind(4, study_id)
            .bind(5, t.stimulus)
            .bind(6, t.practice ? 1 : 0)
            .bind(7, t.is_catch ? 1 : 0);
        if (t.is_catch)
            insert.bind(8, t.catch_id).bind(9, t.prompt).bind(11, t.tolerance);
        insert.bind(10, expected_rating_column(t))
            .bind(12, t.break_before ? 1 : 0)
            .bind(13, new_uuid_v4())
            .bind(14, legacy_task_column(t))
            .bind(15, shown_column(t))
            .bind(16, kind_column(t))
            .bind(17, t.start_value)
            .bind(18, staircase_column(t))
            .run();
    }
    return row;
}

OnlineSession Store::enrol_online(int64_t study_id, const std::string& code,
                                  const OnlineEnrolment& how,
                                  const SessionEnvironment& env) {
    if (how.cells < 1 || !how.plan)
        throw StoreError(db_.path() +
                         ": an online enrolment needs at least one cell and a plan");
    check_stimulus_values(env.stimuli);
    // BEGIN IMMEDIATE: numbers and cell counts read and taken under one write lock.
    Transaction tx(db_);
    OnlineSession out;
    int64_t participant_id = 0;
    Statement find = db_.prepare("SELECT id, number FROM participants WHERE code = ?");
    find.bind(1, code);
    if (find.step()) {
        participant_id = find.integer(0);
        out.number = static_cast<int>(find.integer(1));
    } else {
        out.number = next_participant_number(db_);
        participant_id = insert_participant(db_, study_id, code, out.number);
    }
    std::vector<int64_t> counts(static_cast<size_t>(how.cells), 0);
    Statement per_cell = db_.prepare(online_cell_counts_sql(false));
    per_cell.bind(1, study_id).bind(2, how.active_since_utc);
    while (per_cell.step()) {
        const int64_t cell = per_cell.integer(0);
        if (cell >= 0 && cell < how.cells)
            counts[static_cast<size_t>(cell)] = per_cell.integer(1);
    }
    const auto [cell, allocation] = online_cell(counts, out.number, how.active_since_utc);
    const TrialPlan plan = how.plan(cell);
    if (plan.cell != cell)
        throw StoreError(db_.path() + ": the plan of cell " + std::to_string(cell) +
                         " is cell " + std::to_string(plan.cell));
    out.session = insert_session(
        study_id, participant_id, plan, how.seed, env,
        how.session_uuid.empty() ? new_uuid_v4() : how.session_uuid, allocation);
    out.allocation = allocation;
    if (how.consented)
        db_.prepare("UPDATE sessions SET consent_utc = ? WHERE id = ?")
            .bind(1, utc_now_iso8601())
            .bind(2, out.session.id)
            .run();
    tx.commit();
    return out;
}

namespace {
// A session row from "SELECT s.id, s.uuid, s.participant_id, p.code, s.seed, s.cell,
// s.status ..." stepped onto a row.
SessionRow session_row(const Statement& s) {
    SessionRow row;
    row.id = s.integer(0);
    row.uuid = s.text(1);
    row.participant_id = s.integer(2);
    row.participant = s.text(3);
    row.seed = std::stoull(s.text(4));
    row.cell = static_cast<int>(s.integer(5));
    row.status = s.text(6);
    return row;
}
}  // namespace

std::optional<SessionRow> Store::unfinished_session(const std::string& participant_code) {
    Statement s = db_.prepare(
        "SELECT s.id, s.uuid, s.participant_id, p.code, s.seed, s.cell, s.status "
        "FROM sessions s JOIN participants p ON p.id = s.participant_id "
        "WHERE p.code = ? AND s.status IN ('running', 'paused') ORDER BY s.id DESC LIMIT "
        "1");
    s.bind(1, participant_code);
    if (!s.step()) return std::nullopt;
    return session_row(s);
}

std::optional<SessionRow> Store::session_by_uuid(const std::string& uuid) {
    Statement s = db_.prepare(
        "SELECT s.id, s.uuid, s.participant_id, p.code, s.seed, s.cell, s.status "
        "FROM sessions s JOIN participants p ON p.id = s.participant_id WHERE s.uuid = "
        "?");
    s.bind(1, uuid);
    if (!s.step()) return std::nullopt;
    return session_row(s);
}

bool Store::session_withdrawn(const std::string& uuid) {
    Statement s = db_.prepare("SELECT count(*) FROM withdrawn_sessions WHERE uuid = ?");
    s.bind(1, uuid);
    return s.step() && s.integer(0) > 0;
}

bool Store::has_completed_session(const std::string& participant_code) {
    Statement s = db_.prepare(
        "SELECT count(*) FROM sessions s JOIN participants p ON p.id = s.participant_id "
        "WHERE p.code = ? AND s.status = 'completed'");
    s.bind(1, participant_code);
    return s.step() && s.integer(0) > 0;
}

std::vector<TrialRow> Store::trials(int64_t session_id) {
    Statement s = db_.prepare(
        "SELECT t.id, t.position, t.block, st.stimulus_key, t.practice, t.catch, "
        "coalesce(t.prompt, ''), coalesce(t.expected_rating, 0), t.break_before, "
        "EXISTS (SELECT 1 FROM responses r WHERE r.trial_id = t.id), coalesce(t.uuid, "
        "''), coalesce(t.kind, t.task), coalesce(t.shown, ''), t.start_value, "
        "t.final_value, coalesce(t.staircase, ''), t.intensity, t.skipped, "
        "(SELECT min(r.rating) FROM responses r WHERE r.trial_id = t.id) "
        "FROM trials t JOIN stimuli st ON st.id = t.stimulus_id "
        "WHERE t.session_id = ? ORDER BY t.position");
    s.bind(1, session_id);
    std::vector<TrialRow> out;
    while (s.step()) {
        TrialRow t;
        t.id = s.integer(0);
        t.position = static_cast<int>(s.integer(1));
        t.block = s.text(2);
        t.stimulus = s.text(3);
        t.practice = s.integer(4) != 0;
        t.is_catch = s.integer(5) != 0;
        t.prompt = s.text(6);
        t.expected = static_cast<int>(s.integer(7));
        t.break_before = s.integer(8) != 0;
        t.answered = s.integer(9) != 0;
        t.uuid = s.text(10);
        t.task = task_column(s.is_null(11) ? std::nullopt
                                           : std::optional<std::string>(s.text(11)));
        t.shown = shown_from_text(s.text(12));
        t.start_value = s.optional_real(13);
        t.final_value = s.optional_real(14);
        t.staircase = s.text(15);
        t.intensity = s.optional_real(16);
        t.skipped = s.integer(17) != 0;
        if (t.task != Task::rating && !s.is_null(18))
            t.choice = static_cast<int>(s.integer(18));
        out.push_back(std::move(t));
    }
    return out;
}

void Store::check_stimulus_values(const std::vector<StimulusProvenance>& stimuli) {
    const auto stored = read_resolved_stimuli(db_);
    for (const StimulusProvenance& p : stimuli) {
        const auto it = stored.find(p.stimulus);
        if (it == stored.end()) continue;  // first recorded now
        const std::string difference = resolved_difference(
            p.stimulus, it->second, db_.path(), resolved_of(p), "this run");
        if (!difference.empty())
            throw StoreError(
                db_.path() + ": " + difference +
                ": its pictures would differ from the earlier sessions'; use a "
                "new database");
    }
}

void Store::insert_segment(int64_t session_id, int segment,
                           const SessionEnvironment& env) {
    check_stimulus_values(env.stimuli);
    const int64_t study_id = first_int(
        db_.prepare("SELECT study_id FROM sessions WHERE id = ?").bind(1, session_id));
    // The study's resolved values, recorded by the first session that shows a stimulus.
    Statement first = db_.prepare(
        "UPDATE stimuli SET resolved_mesh = ?, mesh_hash = ? "
        "WHERE study_id = ? AND stimulus_key = ? AND resolved_mesh IS NULL");
    Statement value = db_.prepare(
        "INSERT INTO stimulus_values (stimulus_id, name, value) VALUES "
        "((SELECT id FROM stimuli WHERE study_id = ? AND stimulus_key = ?), ?, ?)");
    for (const StimulusProvenance& p : env.stimuli) {
        first.reset();
        first.bind(1, p.mesh)
            .bind(2, p.mesh_hash)
            .bind(3, study_id)
            .bind(4, p.stimulus)
            .run();
        if (sqlite3_changes(db_.handle()) == 0) continue;
        for (const auto& [name, text] : p.values) {
            value.reset();
            value.bind(1, study_id).bind(2, p.stimulus).bind(3, name).bind(4, text).run();
        }
    }
    Statement segment_row = db_.prepare(
        "INSERT INTO session_segments (session_id, segment, started_utc, "
        "stimulus_source, series_set, " +
        std::string(kEnvironmentColumns) + ") VALUES (?, ?, ?, ?, ?, " +
        environment_values(false, 1) + ")");
    const std::optional<std::string> series_set = series_set_hash(env.series_pictures);
    segment_row.bind(1, session_id)
        .bind(2, segment)
        .bind(3, utc_now_iso8601())
        .bind(4, segment_source(env.stimuli))
        .bind(5, series_set);
    bind_environment(segment_row, 6, env).run();
    const int64_t segment_id = db_.last_insert_id();
    // A set already recorded (an earlier session served from the same files) adds
    // nothing.
    Statement known = db_.prepare(
        "SELECT count(*) FROM series_pictures WHERE study_id = ? AND set_hash = ?");
    known.bind(1, study_id).bind(2, series_set.value_or(""));
    if (series_set && known.step() && known.integer(0) == 0) {
        Statement picture = db_.prepare(
            "INSERT INTO series_pictures (study_id, set_hash, picture, file, "
            "content_hash, "
            "software_version, build_hash) VALUES (?, ?, ?, ?, ?, ?, ?)");
        for (const StimulusProvenance& p : env.series_pictures) {
            picture.reset();
            picture.bind(1, study_id)
                .bind(2, *series_set)
                .bind(3, p.stimulus)
                .bind(4, p.file)
                .bind(5, p.content_hash)
                .bind(6, p.software_version)
                .bind(7, p.build_hash)
                .run();
        }
    }
    Statement shown = db_.prepare(
        "INSERT INTO segment_stimuli (segment_id, stimulus_id, source, file, "
        "content_hash, "
        "software_version, build_hash) VALUES "
        "(?, (SELECT id FROM stimuli WHERE study_id = ? AND stimulus_key = ?), ?, ?, ?, "
        "?, ?)");
    for (const StimulusProvenance& p : env.stimuli) {
        shown.reset();
        shown.bind(1, segment_id)
            .bind(2, study_id)
            .bind(3, p.stimulus)
            .bind(4, p.source)
            .bind(5, p.file)
            .bind(6, p.content_hash)
            .bind(7, p.software_version)
            .bind(8, p.build_hash)
            .run();
    }
}

int Store::begin_segment(int64_t session_id, const SessionEnvironment& env) {
    Transaction tx(db_);
    const int segment = static_cast<int>(first_int(
        db_.prepare("SELECT coalesce(max(segment), 0) + 1 FROM session_segments "
                    "WHERE session_id = ?")
            .bind(1, session_id)));
    insert_segment(session_id, segment, env);
    tx.commit();
    return segment;
}

int Store::resume_segment(int64_t session_id, const SessionEnvironment& env) {
    Transaction tx(db_);
    Statement newest = db_.prepare(
        "SELECT g.id, g.segment, EXISTS (SELECT 1 FROM trials t WHERE t.segment_id = "
        "g.id) "
        "FROM session_segments g WHERE g.session_id = ? ORDER BY g.segment DESC LIMIT 1");
    newest.bind(1, session_id);
    const bool found = newest.step();
    const bool answered_in_it = found && newest.integer(2) != 0;
    const int64_t id = found ? newest.integer(0) : 0;
    const int segment = found ? static_cast<int>(newest.integer(1)) : 0;
    newest.reset();
    if (!found || answered_in_it) {
        tx.commit();  // nothing written yet: the new segment has its own transaction
        return begin_segment(session_id, env);
    }
    // Nothing was answered under the newest segment: it is replaced, not added to.
    db_.prepare("DELETE FROM session_segments WHERE id = ?").bind(1, id).run();
    insert_segment(session_id, segment, env);
    if (segment == 1) copy_environment_to_session_row(session_id, env);
    tx.commit();
    return segment;
}

// The session row keeps the first segment's environment (what older readers show).
void Store::copy_environment_to_session_row(int64_t session_id,
                                            const SessionEnvironment& env) {
    Statement update = db_.prepare("UPDATE sessions SET " +
                                   environment_assignments(false) + " WHERE id = ?");
    bind_environment(update, 1, env).bind(kEnvironmentColumnCount + 1, session_id).run();
}

void Store::update_environment(int64_t session_id, const SessionEnvironment& env) {
    Transaction tx(db_);
    Statement update = db_.prepare(
        "UPDATE session_segments SET " + environment_assignments(false) +
        " WHERE id = (SELECT max(id) FROM session_segments WHERE session_id = ?)");
    bind_environment(update, 1, env).bind(kEnvironmentColumnCount + 1, session_id).run();
    if (first_int(
            db_.prepare("SELECT count(*) FROM session_segments WHERE session_id = ?")
                .bind(1, session_id)) > 1) {
        tx.commit();
        return;
    }
    copy_environment_to_session_row(session_id, env);
    tx.commit();
}

bool Store::add_declined_code(int64_t study_id, const std::string& code,
                              const std::string& page_uuid) {
    std::vector<SaltedCode> held;
    Statement rows =
        db_.prepare("SELECT salt, code_hash FROM declined_codes WHERE study_id = ?");
    rows.bind(1, study_id);
    while (rows.step()) held.push_back({rows.text(0), rows.text(1)});
    const std::optional<SaltedCode> found = find_salted_code(held, code);
    if (!found && held.size() >= static_cast<size_t>(kMaxDeclinedCodes)) return false;
    if (!page_uuid.empty())  // the page is this code's now (a UUID is one page's)
        db_.prepare("UPDATE declined_codes SET page_uuid = NULL WHERE page_uuid = ?")
            .bind(1, page_uuid)
            .run();
    if (found) {
        if (!page_uuid.empty())
            db_.prepare(
                   "UPDATE declined_codes SET page_uuid = ? WHERE salt = ? AND "
                   "code_hash = ?")
                .bind(1, page_uuid)
                .bind(2, found->salt)
                .bind(3, found->code_hash)
                .run();
        return false;
    }
    const SaltedCode row = salted_code(code);
    db_.prepare(
           "INSERT INTO declined_codes (study_id, salt, code_hash, page_uuid) "
           "VALUES (?, ?, ?, ?)")
        .bind(1, study_id)
        .bind(2, row.salt)
        .bind(3, row.code_hash)
        .bind(4, page_uuid.empty() ? std::nullopt : std::optional<std::string>(page_uuid))
        .run();
    return true;
}

bool Store::decline_consent(int64_t study_id, const std::string& code,
                            const std::string& page_uuid) {
    Transaction tx(db_);
    const bool counted = add_declined_code(study_id, code, page_uuid);
    tx.commit();
    return counted;
}

bool Store::consent_declined(const std::string& page_uuid) {
    Statement s = db_.prepare(
        "SELECT EXISTS (SELECT 1 FROM declined_codes WHERE page_uuid = ?1) OR "
        "EXISTS (SELECT 1 FROM declined_pages WHERE uuid = ?1)");
    s.bind(1, page_uuid);
    return s.step() && s.integer(0) != 0;
}

bool Store::forget_declined_session(int64_t session_id) {
    Transaction tx(db_);
    Statement s = db_.prepare(
        "SELECT s.study_id, s.participant_id, p.code FROM sessions s JOIN participants p "
        "ON p.id = s.participant_id WHERE s.id = ? AND s.consent_utc IS NULL "
        "AND NOT EXISTS (SELECT 1 FROM responses r WHERE r.session_id = s.id)");
    s.bind(1, session_id);
    if (!s.step()) return false;
    const int64_t study_id = s.integer(0), participant_id = s.integer(1);
    const std::string code = s.text(2);
    s.reset();
    db_.prepare("DELETE FROM sessions WHERE id = ?").bind(1, session_id).run();
    db_.prepare(
           "DELETE FROM participants WHERE id = ? AND NOT EXISTS "
           "(SELECT 1 FROM sessions WHERE participant_id = ?)")
        .bind(1, participant_id)
        .bind(2, participant_id)
        .run();
    add_declined_code(study_id, code, "");
    tx.commit();
    return true;
}

void Store::set_consent(int64_t session_id) {
    db_.prepare("UPDATE sessions SET consent_utc = ? WHERE id = ?")
        .bind(1, utc_now_iso8601())
        .bind(2, session_id)
        .run();
}

bool Store::has_consent(int64_t session_id) {
    Statement s =
        db_.prepare("SELECT consent_utc IS NOT NULL FROM sessions WHERE id = ?");
    s.bind(1, session_id);
    return s.step() && s.integer(0) != 0;
}

std::optional<std::string> Store::web_position(int64_t session_id) {
    Statement s = db_.prepare("SELECT web_position FROM sessions WHERE id = ?");
    s.bind(1, session_id);
    if (!s.step() || s.is_null(0)) return std::nullopt;
    return s.text(0);
}

void Store::set_web_position(int64_t session_id, const std::string& position) {
    db_.prepare("UPDATE sessions SET web_position = ? WHERE id = ?")
        .bind(1, position)
        .bind(2, session_id)
        .run();
}

bool Store::record_trial(int64_t session_id, int64_t trial_id,
                         const TrialOutcome& outcome) {
    Transaction tx(db_);
    TrialAnswerFacts known;
    std::string block;
    {
        Statement facts = db_.prepare(
            "SELECT t.block, coalesce(t.kind, t.task), t.skipped, coalesce(t.staircase, "
            "''), EXISTS (SELECT 1 FROM responses r WHERE r.trial_id = t.id) "
            "FROM trials t WHERE t.id = ? AND t.session_id = ?");
        facts.bind(1, trial_id).bind(2, session_id);
        if (facts.step()) {
            known.part_of_session = true;
            block = facts.text(0);
            known.kind =
                task_column(facts.is_null(1) ? std::nullopt
                                             : std::optional<std::string>(facts.text(1)));
            known.skipped = facts.integer(2) != 0;
            known.staircase = facts.text(3);
            known.answered = facts.integer(4) != 0;
        }
    }
    check_trial_answer(db_.path(), session_id, trial_id, known,
                       questions_of_session(session_id).of_block(block), outcome);
    Statement insert =
        db_.prepare("INSERT INTO responses (session_id, trial_id, " +
                    std::string(kResponseColumns) + ") VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
    for (const Response& r : outcome.responses) {
        insert.reset();
        insert.bind(1, session_id)
            .bind(2, trial_id)
            .bind(3, r.question)
            .bind(4, r.rating)
            .bind(5, r.rt_ms)
            .bind(6, r.changes)
            .bind(7, r.first_choice_ns)
            .bind(8, r.final_choice_ns)
            .run();
    }
    // The trial belongs to the segment on screen: the session's newest.
    db_.prepare(
           "UPDATE trials SET onset_ns = ?, confirm_ns = ?, dropped_frames = ?, "
           "answered_utc = ?, segment_id = (SELECT max(id) FROM session_segments "
           "WHERE session_id = ?), final_value = ?, intensity = ? WHERE id = ?")
        .bind(1, outcome.onset_ns)
        .bind(2, outcome.confirm_ns)
        .bind(3, outcome.dropped_frames)
        .bind(4, utc_now_iso8601())
        .bind(5, session_id)
        .bind(6, outcome.final_value)
        .bind(7, outcome.intensity)
        .bind(8, trial_id)
        .run();
    Statement adjustment = db_.prepare(
        "INSERT INTO adjustments (trial_id, step, value, t_ns, input) VALUES (?, ?, ?, "
        "?, "
        "?)");
    for (size_t k = 0; k < outcome.adjustments.size(); ++k) {
        const Adjustment& a = outcome.adjustments[k];
        adjustment.reset();
        adjustment.bind(1, trial_id)
            .bind(2, static_cast<int64_t>(k + 1))
            .bind(3, a.value)
            .bind(4, a.t_ns)
            .bind(5, a.input)
            .run();
    }
    // The procedure has finished: its slots still open in this block are skipped.
    if (outcome.finishes_staircase)
        db_.prepare(
               "UPDATE trials SET skipped = 1 WHERE session_id = ? AND block = ? AND "
               "staircase = ? AND id <> ? AND " +
               open_trial_sql("trials"))
            .bind(1, session_id)
            .bind(2, block)
            .bind(3, known.staircase)
            .bind(4, trial_id)
            .run();
    const bool completed = complete_session_if_answered(session_id);  // same transaction
    tx.commit();
    return completed;
}

bool Store::complete_session_if_answered(int64_t session_id) {
    db_.prepare(
           "UPDATE sessions SET status = 'completed', ended_utc = coalesce(ended_utc, ?) "
           "WHERE id = ? AND status != 'completed' AND NOT EXISTS (SELECT 1 FROM trials "
           "t WHERE t.session_id = sessions.id AND " +
           open_trial_sql() + ")")
        .bind(1, utc_now_iso8601())
        .bind(2, session_id)
        .run();
    Statement s = db_.prepare("SELECT status = 'completed' FROM sessions WHERE id = ?");
    s.bind(1, session_id);
    return s.step() && s.integer(0) != 0;
}

const StudyQuestions& Store::questions_of_session(int64_t session_id) {
    auto it = questions_by_session_.find(session_id);
    if (it != questions_by_session_.end()) return it->second;
    Statement s = db_.prepare("SELECT study_id FROM sessions WHERE id = ?");
    s.bind(1, session_id);
    if (!s.step())
        throw StoreError(db_.path() + ": no session " + std::to_string(session_id));
    return questions_by_session_
        .emplace(session_id, stored_study_questions(db_, s.integer(0)))
        .first->second;
}

void Store::set_status(int64_t session_id, const std::string& status, bool ended) {
    {
        Statement current = db_.prepare("SELECT status, uuid FROM sessions WHERE id = ?");
        current.bind(1, session_id);
        if (current.step())
            check_status_change(db_.path(), current.text(1), current.text(0), status);
    }
    if (ended) {
        db_.prepare("UPDATE sessions SET status = ?, ended_utc = ? WHERE id = ?")
            .bind(1, status)
            .bind(2, utc_now_iso8601())
            .bind(3, session_id)
            .run();
    } else {
        db_.prepare("UPDATE sessions SET status = ?, ended_utc = NULL WHERE id = ?")
            .bind(1, status)
            .bind(2, session_id)
            .run();
    }
}

bool Store::withdraw_participant(const std::string& code) {
    Transaction tx(db_);
    // Tombstones first (withdrawal.h), in the same transaction as the delete: the
    // sessions' UUIDs and the (code, machine) hashes, so no merge brings them back.
    const std::string now = utc_now_iso8601();
    std::vector<std::pair<std::string, std::string>> sessions;  // uuid, machine
    {
        Statement s = db_.prepare(
            "SELECT se.uuid, se.machine_id FROM sessions se JOIN "
            "participants p ON p.id = se.participant_id WHERE p.code = ?");
        s.bind(1, code);
        while (s.step()) sessions.emplace_back(s.text(0), s.text(1));
    }
    if (first_int(db_.prepare("SELECT count(*) FROM participants WHERE code = ?")
                      .bind(1, code)) > 0) {
        Tombstones tombstones;
        for (const auto& [uuid, machine] : sessions) tombstones.add_session(uuid, now);
        for (const WithdrawnCode& c : code_tombstones(code, sessions, now))
            tombstones.add_code(c);
        tombstones.write(db_);
    }
    db_.prepare(
           "INSERT OR IGNORE INTO retired_participant_numbers (number) "
           "SELECT number FROM participants WHERE code = ?")
        .bind(1, code)
        .run();
    db_.prepare("DELETE FROM participants WHERE code = ?").bind(1, code).run();
    const bool deleted = sqlite3_changes(db_.handle()) > 0;
    tx.commit();
    return deleted;
}

std::optional<ParticipantCounts> Store::participant_counts(const std::string& code) {
    Statement s = db_.prepare(
        "SELECT count(DISTINCT se.id), count(r.id) FROM participants p "
        "LEFT JOIN sessions se ON se.participant_id = p.id "
        "LEFT JOIN responses r ON r.session_id = se.id WHERE p.code = ? GROUP BY p.id");
    s.bind(1, code);
    if (!s.step()) return std::nullopt;
    return ParticipantCounts{s.integer(0), s.integer(1)};
}

void Store::snapshot_to_sqlite(const std::string& sqlite_path) {
    db_.prepare("VACUUM INTO ?").bind(1, sqlite_path).run();
}

void Store::claim_participant(const std::string& code) {
    if (claim_fd_ < 0) {
        const std::string lock_path = db_.path() + "-participants.lock";
        claim_fd_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (claim_fd_ < 0)
            throw StoreError(lock_path + ": cannot open the participant lock file: " +
                             std::strerror(errno));
    }
    // One byte per code (a 62-bit hash of it) locked for this open file description:
    // a second store, in this process or another, cannot take it while this one lives.
    if (claimed_.count(code)) return;
    struct flock lock {};
    lock.l_type = F_WRLCK;
    lock.l_whence = SEEK_SET;
    lock.l_start =
        static_cast<off_t>(std::hash<std::string>{}(code)&0x3FFFFFFFFFFFFFFFull);
    lock.l_len = 1;
    if (fcntl(claim_fd_, F_OFD_SETLK, &lock) != 0)
        throw StoreError(
            db_.path() + ": participant '" + code +
            "' is in a session on this machine now; refusing to run it twice "
            "at once");
    claimed_[code] = lock.l_start;
}

void Store::release_participant(const std::string& code) {
    const auto it = claimed_.find(code);
    if (it == claimed_.end()) return;
    const int64_t byte = it->second;
    claimed_.erase(it);
    // Two codes of one byte (a hash collision) share the lock: it ends with the last.
    for (const auto& [other, other_byte] : claimed_)
        if (other_byte == byte) return;
    struct flock lock {};
    lock.l_type = F_UNLCK;
    lock.l_whence = SEEK_SET;
    lock.l_start = static_cast<off_t>(byte);
    lock.l_len = 1;
    fcntl(claim_fd_, F_OFD_SETLK, &lock);
}

Store::~Store() {
    if (claim_fd_ >= 0) ::close(claim_fd_);  // releases the claims
}

}  // namespace lucent::study
