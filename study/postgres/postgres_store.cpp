// The PostgreSQL study store (postgres_store.h). Every statement goes through
// exec_params with $n parameters; the only SQL built from strings is constant text.
// A call of one statement runs it alone (pqxx::nontransaction: atomic by itself) rather
// than between BEGIN and COMMIT, two round trips fewer; `lucent serve` makes several
// such calls per request.
//
// [1] connection  [2] studies, participants, claims  [3] sessions, segments
// [5] status, withdrawal, counts. The connection's error handling is
// server_connection.h, the schema postgres_schema.cpp, [4] trials postgres_trials.cpp,
// [6] the snapshot into a study file postgres_snapshot.cpp.
#include "study/postgres/postgres_store.h"

#include <chrono>
#include <pqxx/pqxx>

#include "study/postgres/server_connection.h"
#include "study/schema.h"
#include "study/store_rules.h"
#include "study/time_and_ids.h"
#include "study/withdrawal.h"

namespace lucent::study {
using namespace postgres_internal;

// ---- [1] connection -------------------------------------------------------------------

std::string checked_server_uri(const std::string& uri) {
    const size_t scheme_end = uri.find("://");
    if (scheme_end == std::string::npos)
        throw StoreError(uri + ": not a postgresql:// URI");
    const size_t authority_end = uri.find_first_of("/?", scheme_end + 3);
    const std::string authority =
        uri.substr(scheme_end + 3, authority_end - scheme_end - 3);
    const size_t at = authority.rfind('@');
    const bool password_in_user =
        at != std::string::npos && authority.substr(0, at).find(':') != std::string::npos;
    const size_t query = uri.find('?');
    const bool password_param = query != std::string::npos &&
                                (uri.find("?password=", query) != std::string::npos ||
                                 uri.find("&password=", query) != std::string::npos);
    if (password_in_user || password_param)
        throw StoreError(
            "--db: the server URI holds a password; give it through PGPASSWORD or "
            "~/.pgpass (PGPASSFILE), never on the command line");
    if (uri.find("connect_timeout=") != std::string::npos) return uri;
    return uri + (query == std::string::npos ? "?" : "&") + "connect_timeout=5";
}

PostgresStore::PostgresStore(const std::string& uri, const StoreOptions& options)
    : uri_(checked_server_uri(uri)),
      name_(uri),
      options_(options),
      journal_(options.journal
                   ? std::make_unique<TrialJournal>(options.journal_path.empty()
                                                        ? default_journal_path(uri)
                                                        : options.journal_path,
                                                    uri)
                   : nullptr) {
    // Refuse an uninitialised or newer schema now, with one line, before any session.
    guarded("opening", [&] {
        pqxx::work tx(connection());
        const pqxx::result has = tx.exec_params(
            "SELECT to_regclass('lucent_schema') IS NOT NULL, to_regclass('studies') IS "
            "NOT NULL");
        if (!has[0][0].as<bool>()) {
            throw StoreError(name_ +
                             (has[0][1].as<bool>()
                                  ? ": holds tables but no lucent_schema: not a Lucent "
                                    "study database; left unchanged"
                                  : ": no Lucent schema yet; run 'lucent store init "
                                    "--db URI' first"));
        }
        const pqxx::result v =
            tx.exec_params("SELECT application_id, version FROM lucent_schema");
        if (v.empty() || v[0][0].as<int64_t>() != kApplicationId)
            throw StoreError(name_ + ": lucent_schema is not Lucent's; left unchanged");
        const int version = v[0][1].as<int>();
        if (version > kSchemaVersion)
            throw StoreError(name_ + ": written by a newer Lucent (schema " +
                             std::to_string(version) + ", this build knows " +
                             std::to_string(kSchemaVersion) + "); left unchanged");
        if (version < kSchemaVersion)
            throw StoreError(name_ + ": schema " + std::to_string(version) +
                             " is older than this build's " +
                             std::to_string(kSchemaVersion) +
                             "; run 'lucent store init --db URI' to migrate it");
        tx.commit();
        return 0;
    });
}

// Claims are released before the connection closes, not left to the server: a backend
// frees its session locks only when it has noticed the disconnect, so a browser or a
// station claiming the same participant right after this store closed could still be
// refused (seen on a fresh machine). Failures are ignored: a closed connection holds
// nothing.
PostgresStore::~PostgresStore() {
    const std::set<std::string> claimed = claimed_;
    for (const std::string& code : claimed) release_participant(code);
}

PostgresStore::Connection& PostgresStore::connection() {
    if (conn_ && conn_->is_open()) return *conn_;
    conn_.reset();
    try {
        conn_ = std::make_unique<Connection>(uri_);
    } catch (const pqxx::broken_connection& e) {
        throw Unreachable(name_ + ": cannot reach the server: " + first_line(e.what()));
    } catch (const std::exception& e) {
        throw Unreachable(name_ + ": cannot connect: " + first_line(e.what()));
    }
    // Claims live as long as a connection: take them again on the new one.
    for (const std::string& code : claimed_) {
        pqxx::nontransaction n(*conn_);
        n.exec_params("SELECT pg_try_advisory_lock(hashtextextended($1, 0))",
                      "lucent participant " + code);
    }
    return *conn_;
}

void PostgresStore::drop_connection() { conn_.reset(); }

const std::string& PostgresStore::journal_path() const {
    static const std::string none;
    return journal_ ? journal_->path() : none;
}

// ---- [2] studies, participants, claims -----------------------------------------------

int64_t PostgresStore::ensure_study(const Protocol& protocol) {
    const std::string hash = protocol_hash(protocol.text);
    return guarded("storing the study", [&]() -> int64_t {
        pqxx::work tx(connection());
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", kLockClass, kStudyLock);
        for (const pqxx::row& r :
             tx.exec_params("SELECT id, protocol_hash, name FROM studies")) {
            if (r[1].as<std::string>() == hash) return r[0].as<int64_t>();
            throw StoreError(name_ + ": holds study '" + r[2].as<std::string>() +
                             "' (protocol " + r[1].as<std::string>().substr(0, 12) +
                             "), not this protocol (" + hash.substr(0, 12) +
                             "); use a new database per protocol");
        }
        const int64_t study_id =
            tx.exec_params1(
                  "INSERT INTO studies (name, protocol_text, protocol_hash, "
                  "created_utc) VALUES ($1, $2, $3, $4) RETURNING id",
                  protocol.name, protocol.text, hash, utc_now_iso8601())[0]
                .as<int64_t>();
        for (const Stimulus& s : protocol.stimuli) {
            std::string varies;
            for (const std::string& v : s.varies)
                varies += (varies.empty() ? "" : " ") + v;
            const int64_t stimulus_id =
                tx.exec_params1(
                      "INSERT INTO stimuli (study_id, stimulus_key, technique, mesh, "
                      "image, varies) VALUES ($1, $2, $3, $4, $5, $6) RETURNING id",
                      study_id, s.id, s.technique, s.mesh, s.image, varies)[0]
                    .as<int64_t>();
            for (const auto& [name, value] : s.columns())
                tx.exec_params(
                    "INSERT INTO stimulus_parameters (stimulus_id, name, value) "
                    "VALUES ($1, $2, $3)",
                    stimulus_id, name, value);
        }
        tx.commit();
        return study_id;
    });
}

namespace {

// Enrolment order: one past the highest number held, not the count, which falls after a
// withdrawal and would hand out a number (a Latin-square row) still in use. The caller
// holds the number lock until the number is taken.
int next_participant_number(pqxx::work& tx) {
    return tx.exec_params1(
                 "SELECT greatest(coalesce((SELECT max(number) FROM participants), 0), "
                 "coalesce((SELECT max(number) FROM retired_participant_numbers), 0))")[0]
               .as<int>() +
           1;
}

// The participant's row, enrolled now; its id.
int64_t insert_participant(pqxx::work& tx, int64_t study_id, const std::string& code,
                           int number) {
    return tx
        .exec_params1(
            "INSERT INTO participants (study_id, code, number, created_utc) "
            "VALUES ($1, $2, $3, $4) RETURNING id",
            study_id, code, number, utc_now_iso8601())[0]
        .as<int64_t>();
}

}  // namespace

int64_t PostgresStore::ensure_participant(int64_t study_id, const std::string& code,
                                          int* number) {
    return guarded("enrolling the participant", [&]() -> int64_t {
        pqxx::work tx(connection());
        // One station at a time reads the highest number and takes the next: no two
        // participants get one number (one Latin-square row) from racing stations.
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", kLockClass, kNumberLock);
        const pqxx::result found =
            tx.exec_params("SELECT id, number FROM participants WHERE code = $1", code);
        if (!found.empty()) {
            if (number) *number = found[0][1].as<int>();
            return found[0][0].as<int64_t>();
        }
        int n = participant_number_from_code(code);
        if (n < 0) n = next_participant_number(tx);
        const int64_t id = insert_participant(tx, study_id, code, n);
        tx.commit();
        if (number) *number = n;
        return id;
    });
}

void PostgresStore::claim_participant(const std::string& code) {
    if (claimed_.count(code)) return;
    const bool taken = guarded("claiming the participant", [&] {
        pqxx::nontransaction n(connection());
        return n
            .exec_params1("SELECT pg_try_advisory_lock(hashtextextended($1, 0))",
                          "lucent participant " + code)[0]
            .as<bool>();
    });
    if (!taken)
        throw StoreError(
            name_ + ": participant '" + code +
            "' is in a session on another station now; refusing to run it twice "
            "at once");
    claimed_.insert(code);
}

void PostgresStore::release_participant(const std::string& code) {
    if (!claimed_.erase(code)) return;
    if (!conn_ || !conn_->is_open())
        return;  // the server ended the session's locks with it
    try {
        pqxx::nontransaction n(*conn_);
        n.exec_params("SELECT pg_advisory_unlock(hashtextextended($1, 0))",
                      "lucent participant " + code);
    } catch (const std::exception&) {
        drop_connection();  // a connection in doubt holds nothing once closed
    }
}

void PostgresStore::check_stimulus_values(
    const std::vector<StimulusProvenance>& stimuli) {
    guarded("checking stimulus values", [&] {
        pqxx::work tx(connection());
        std::map<std::string, ResolvedStimulus> stored;
        for (const pqxx::row& r : tx.exec_params(
                 "SELECT stimulus_key, technique, resolved_mesh, mesh_hash FROM stimuli "
                 "WHERE resolved_mesh IS NOT NULL"))
            stored[r[0].as<std::string>()] = {
                r[1].as<std::string>(),
                r[2].as<std::string>(),
                r[3].is_null() ? "" : r[3].as<std::string>(),
                {}};
        for (const pqxx::row& r : tx.exec_params(
                 "SELECT st.stimulus_key, v.name, v.value FROM stimulus_values v "
                 "JOIN stimuli st ON st.id = v.stimulus_id"))
            stored[r[0].as<std::string>()].values[r[1].as<std::string>()] =
                r[2].as<std::string>();
        for (const StimulusProvenance& p : stimuli) {
            const auto it = stored.find(p.stimulus);
            if (it == stored.end()) continue;
            const std::string difference = resolved_difference(
                p.stimulus, it->second, name_, resolved_of(p), "this run");
            if (!difference.empty())
                throw StoreError(
                    name_ + ": " + difference +
                    ": its pictures would differ from the earlier sessions'; use a "
                    "new database");
        }
        return 0;
    });
}

// ---- [3] sessions, segments -----------------------------------------------------------

namespace {

// `sql` run with the environment's values as $1..$9 (schema.h: kEnvironmentColumns), then
// `more` from $10 on.
template <class... More>
pqxx::result exec_with_environment(pqxx::work& tx, const std::string& sql,
                                   const SessionEnvironment& env, const More&... more) {
    return tx.exec_params(sql, env.machine_id, env.software_version, env.build_hash,
                          env.gl_vendor, env.gl_renderer, env.display_mode,
                          env.display_refresh_hz, env.measured_refresh_hz,
                          env.refresh_note, more...);
}

// The session row keeps the first segment's environment (what older readers show).
void copy_environment_to_session_row(pqxx::work& tx, int64_t session_id,
                                     const SessionEnvironment& env) {
    exec_with_environment(
        tx, "UPDATE sessions SET " + environment_assignments(true) + " WHERE id = $10",
        env, session_id);
}

// The segment rows and (first time) the study's resolved values, inside `tx`.
void insert_segment(pqxx::work& tx, int64_t session_id, int segment,
                    const SessionEnvironment& env) {
    const int64_t study_id =
        tx.exec_params1("SELECT study_id FROM sessions WHERE id = $1", session_id)[0]
            .as<int64_t>();
    for (const StimulusProvenance& p : env.stimuli) {
        // Row lock: a station racing to record the same stimulus first waits, then sees
        // it recorded (affected rows 0) and does not add values twice.
        const pqxx::result first = tx.exec_params(
            "UPDATE stimuli SET resolved_mesh = $1, mesh_hash = $2 WHERE study_id = $3 "
            "AND "
            "stimulus_key = $4 AND resolved_mesh IS NULL",
            p.mesh, p.mesh_hash, study_id, p.stimulus);
        if (first.affected_rows() == 0) continue;
        for (const auto& [name, text] : p.values)
            tx.exec_params(
                "INSERT INTO stimulus_values (stimulus_id, name, value) VALUES "
                "((SELECT id FROM stimuli WHERE study_id = $1 AND stimulus_key = $2), "
                "$3, $4)",
                study_id, p.stimulus, name, text);
    }
    const std::optional<std::string> series_set = series_set_hash(env.series_pictures);
    const int64_t segment_id =
        exec_with_environment(
            tx,
            "INSERT INTO session_segments (" + std::string(kEnvironmentColumns) +
                ", session_id, segment, started_utc, stimulus_source, series_set) "
                "VALUES (" +
                environment_values(true, 1) + ", $10, $11, $12, $13, $14) RETURNING id",
            env, session_id, segment, utc_now_iso8601(), segment_source(env.stimuli),
            series_set)[0][0]
            .as<int64_t>();
    // One row per picture of each distinct set; instances racing to record one set both
    // insert, and the primary key keeps one of each.
    if (series_set &&
        tx.exec_params("SELECT 1 FROM series_pictures WHERE study_id = $1 AND set_hash = "
                       "$2 LIMIT 1",
                       study_id, *series_set)
            .empty())
        for (const StimulusProvenance& p : env.series_pictures)
            tx.exec_params(
                "INSERT INTO series_pictures (study_id, set_hash, picture, file, "
                "content_hash, software_version, build_hash) VALUES ($1, $2, $3, $4, $5, "
                "$6, $7) ON CONFLICT DO NOTHING",
                study_id, *series_set, p.stimulus, p.file, p.content_hash,
                p.software_version, p.build_hash);
    for (const StimulusProvenance& p : env.stimuli)
        tx.exec_params(
            "INSERT INTO segment_stimuli (segment_id, stimulus_id, source, file, "
            "content_hash, software_version, build_hash) VALUES ($1, (SELECT id FROM "
            "stimuli WHERE study_id = $2 AND stimulus_key = $3), $4, $5, $6, $7, $8)",
            segment_id, study_id, p.stimulus, p.source, p.file, p.content_hash,
            p.software_version, p.build_hash);
}

SessionRow session_row(const pqxx::row& r) {
    SessionRow row;
    row.id = r[0].as<int64_t>();
    row.uuid = r[1].as<std::string>();
    row.participant_id = r[2].as<int64_t>();
    row.participant = r[3].as<std::string>();
    row.seed = std::stoull(r[4].as<std::string>());
    row.cell = r[5].as<int>();
    row.status = r[6].as<std::string>();
    return row;
}

}  // namespace

namespace {

// The session row, its first segment and its trials, inside `tx`.
SessionRow insert_session(pqxx::work& tx, int64_t study_id, int64_t participant_id,
                          const TrialPlan& plan, uint64_t seed,
                          const SessionEnvironment& env, const std::string& uuid,
                          const std::optional<std::string>& allocation) {
    SessionRow row = new_session_row(uuid, participant_id, seed, plan);
    {
        row.id =
            exec_with_environment(
                tx,
                "INSERT INTO sessions (" + std::string(kEnvironmentColumns) +
                    ", uuid, study_id, participant_id, seed, cell, block_order, "
                    "status, started_utc, allocation) VALUES (" +
                    environment_values(true, 1) +
                    ", $10, $11, $12, $13, $14, $15, 'running', $16, $17) "
                    "RETURNING id",
                env, row.uuid, study_id, participant_id, std::to_string(seed), plan.cell,
                block_order_text(plan), utc_now_iso8601(), allocation)[0][0]
                .as<int64_t>();
        row.participant = tx.exec_params1("SELECT code FROM participants WHERE id = $1",
                                          participant_id)[0]
                              .as<std::string>();
        insert_segment(tx, row.id, 1, env);
        for (const PlannedTrial& t : plan.trials) {
            std::optional<std::string> catch_id, prompt;
            std::optional<int> tolerance;
            const std::optional<int> expected = expected_rating_column(t);
            if (t.is_catch) {
                catch_id = t.catch_id;
                prompt = t.prompt;
                tolerance = t.tolerance;
            }
            tx.exec_params(
                "INSERT INTO trials (session_id, position, block, stimulus_id, "
                "practice, catch, catch_id, prompt, expected_rating, tolerance, "
                "break_before, uuid, task, shown, kind, start_value, staircase) VALUES "
                "($1, $2, $3, (SELECT id FROM stimuli WHERE study_id = $4 AND "
                "stimulus_key = $5), $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, "
                "$17, $18)",
                row.id, t.position, t.block, study_id, t.stimulus, t.practice ? 1 : 0,
                t.is_catch ? 1 : 0, catch_id, prompt, expected, tolerance,
                t.break_before ? 1 : 0, new_uuid_v4(), legacy_task_column(t),
                shown_column(t), kind_column(t), t.start_value, staircase_column(t));
        }
    }
    return row;
}

}  // namespace

SessionRow PostgresStore::create_session(int64_t study_id, int64_t participant_id,
                                         const TrialPlan& plan, uint64_t seed,
                                         const SessionEnvironment& env) {
    check_stimulus_values(env.stimuli);
    const std::string uuid = new_uuid_v4();
    return guarded("creating the session", [&] {
        pqxx::work tx(connection());
        SessionRow row = insert_session(tx, study_id, participant_id, plan, seed, env,
                                        uuid, std::nullopt);
        tx.commit();
        return row;
    });
}

OnlineSession PostgresStore::enrol_online(int64_t study_id, const std::string& code,
                                          const OnlineEnrolment& how,
                                          const SessionEnvironment& env) {
    if (how.cells < 1 || !how.plan)
        throw StoreError(name_ +
                         ": an online enrolment needs at least one cell and a plan");
    check_stimulus_values(env.stimuli);
    const std::string uuid = how.session_uuid.empty() ? new_uuid_v4() : how.session_uuid;
    return guarded("enrolling the participant", [&] {
        pqxx::work tx(connection());
        // The number lock: stations and serve processes on this server take numbers and
        // count cells one at a time, so arrivals never share a number and cells stay
        // balanced across processes.
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", kLockClass, kNumberLock);
        OnlineSession out;
        int64_t participant_id = 0;
        const pqxx::result found =
            tx.exec_params("SELECT id, number FROM participants WHERE code = $1", code);
        if (!found.empty()) {
            participant_id = found[0][0].as<int64_t>();
            out.number = found[0][1].as<int>();
        } else {
            out.number = next_participant_number(tx);
            participant_id = insert_participant(tx, study_id, code, out.number);
        }
        std::vector<int64_t> counts(static_cast<size_t>(how.cells), 0);
        for (const pqxx::row& r : tx.exec_params(online_cell_counts_sql(true), study_id,
                                                 how.active_since_utc)) {
            const int64_t cell = r[0].as<int64_t>();
            if (cell >= 0 && cell < how.cells)
                counts[static_cast<size_t>(cell)] = r[1].as<int64_t>();
        }
        const auto [cell, allocation] =
            online_cell(counts, out.number, how.active_since_utc);
        const TrialPlan plan = how.plan(cell);
        if (plan.cell != cell)
            throw StoreError(name_ + ": the plan of cell " + std::to_string(cell) +
                             " is cell " + std::to_string(plan.cell));
        out.session = insert_session(tx, study_id, participant_id, plan, how.seed, env,
                                     uuid, allocation);
        out.allocation = allocation;
        if (how.consented)
            tx.exec_params("UPDATE sessions SET consent_utc = $1 WHERE id = $2",
                           utc_now_iso8601(), out.session.id);
        tx.commit();
        return out;
    });
}

std::optional<SessionRow> PostgresStore::unfinished_session(const std::string& code) {
    return guarded("finding the session", [&]() -> std::optional<SessionRow> {
        pqxx::nontransaction tx(connection());
        const pqxx::result r = tx.exec_params(
            "SELECT s.id, s.uuid, s.participant_id, p.code, s.seed, s.cell, s.status "
            "FROM sessions s JOIN participants p ON p.id = s.participant_id "
            "WHERE p.code = $1 AND s.status IN ('running', 'paused') ORDER BY s.id DESC "
            "LIMIT 1",
            code);
        if (r.empty()) return std::nullopt;
        return session_row(r[0]);
    });
}

std::optional<SessionRow> PostgresStore::session_by_uuid(const std::string& uuid) {
    return guarded("finding the session", [&]() -> std::optional<SessionRow> {
        pqxx::nontransaction tx(connection());
        const pqxx::result r = tx.exec_params(
            "SELECT s.id, s.uuid, s.participant_id, p.code, s.seed, s.cell, s.status "
            "FROM sessions s JOIN participants p ON p.id = s.participant_id "
            "WHERE s.uuid = $1",
            uuid);
        if (r.empty()) return std::nullopt;
        return session_row(r[0]);
    });
}

bool PostgresStore::session_withdrawn(const std::string& uuid) {
    return guarded("finding the session", [&] {
        pqxx::nontransaction tx(connection());
        return !tx.exec_params("SELECT 1 FROM withdrawn_sessions WHERE uuid = $1", uuid)
                    .empty();
    });
}

bool PostgresStore::has_completed_session(const std::string& code) {
    return guarded("finding the session", [&] {
        pqxx::nontransaction tx(connection());
        return tx.exec_params1(
                     "SELECT count(*) FROM sessions s JOIN participants p ON "
                     "p.id = s.participant_id WHERE p.code = $1 AND "
                     "s.status = 'completed'",
                     code)[0]
                   .as<int64_t>() > 0;
    });
}

std::vector<TrialRow> PostgresStore::trials(int64_t session_id) {
    std::vector<TrialRow> out = guarded("reading the trials", [&] {
        pqxx::work tx(connection());
        std::vector<TrialRow> rows;
        for (
            const pqxx::row& r : tx.exec_params(
                "SELECT t.id, t.position, t.block, st.stimulus_key, t.practice, t.catch, "
                "coalesce(t.prompt, ''), coalesce(t.expected_rating, 0), t.break_before, "
                "EXISTS (SELECT 1 FROM responses r WHERE r.trial_id = t.id), "
                "coalesce(t.uuid, ''), coalesce(t.kind, t.task), coalesce(t.shown, ''), "
                "t.start_value, t.final_value, coalesce(t.staircase, ''), t.intensity, "
                "t.skipped, (SELECT min(r.rating) FROM responses r WHERE r.trial_id = "
                "t.id) FROM trials t JOIN stimuli st ON st.id = t.stimulus_id "
                "WHERE t.session_id = $1 ORDER BY t.position",
                session_id)) {
            TrialRow t;
            t.id = r[0].as<int64_t>();
            t.position = r[1].as<int>();
            t.block = r[2].as<std::string>();
            t.stimulus = r[3].as<std::string>();
            t.practice = r[4].as<int>() != 0;
            t.is_catch = r[5].as<int>() != 0;
            t.prompt = r[6].as<std::string>();
            t.expected = r[7].as<int>();
            t.break_before = r[8].as<int>() != 0;
            t.answered = r[9].as<bool>();
            t.uuid = r[10].as<std::string>();
            t.task = task_column(r[11].as<std::optional<std::string>>());
            t.shown = shown_from_text(r[12].as<std::string>());
            t.start_value = optional_double(r[13]);
            t.final_value = optional_double(r[14]);
            t.staircase = r[15].as<std::string>();
            t.intensity = optional_double(r[16]);
            t.skipped = r[17].as<int>() != 0;
            if (t.task != Task::rating && !r[18].is_null()) t.choice = r[18].as<int>();
            rows.push_back(std::move(t));
        }
        return rows;
    });
    // What this station journaled but the server has not confirmed counts as answered,
    // as it was journaled, and the slots its finishing answers skipped as skipped.
    SessionCache& cache = session_cache(session_id);
    std::vector<std::pair<std::string, std::string>> finished;  // block, staircase
    for (TrialRow& t : out) {
        cache.trial_uuid[t.id] = t.uuid;
        cache.trial_block[t.id] = t.block;
        cache.trial_kind[t.id] = t.task;
        cache.trial_staircase[t.id] = t.staircase;
        if (t.skipped) cache.skipped.insert(t.id);
        if (t.answered) {
            cache.answered.insert(t.id);
            continue;
        }
        const std::optional<JournaledTrial> journaled =
            journal_ ? journal_->find(t.uuid) : std::nullopt;
        if (!journaled) continue;
        t.answered = true;
        cache.answered.insert(t.id);
        t.final_value = journaled->outcome.final_value;
        t.intensity = journaled->outcome.intensity;
        if (t.task != Task::rating && journaled->outcome.responses.size() == 1)
            t.choice = journaled->outcome.responses[0].rating;
        if (journaled->outcome.finishes_staircase)
            finished.emplace_back(t.block, t.staircase);
    }
    for (TrialRow& t : out)
        for (const auto& [block, staircase] : finished)
            if (!t.answered && t.block == block && t.staircase == staircase) {
                t.skipped = true;
                cache.skipped.insert(t.id);
            }
    return out;
}

PostgresStore::SessionCache& PostgresStore::session_cache(int64_t session_id) {
    auto it = sessions_.find(session_id);
    if (it != sessions_.end()) return it->second;
    SessionCache cache = guarded("reading the session", [&] {
        pqxx::work tx(connection());
        const pqxx::result r = tx.exec_params(
            "SELECT s.uuid, st.name, st.protocol_text FROM sessions s JOIN studies st ON "
            "st.id = s.study_id WHERE s.id = $1",
            session_id);
        if (r.empty())
            throw StoreError(name_ + ": no session " + std::to_string(session_id));
        SessionCache c;
        c.uuid = r[0][0].as<std::string>();
        try {
            c.questions = study_questions(
                parse_protocol(r[0][2].as<std::string>(),
                               name_ + " (study '" + r[0][1].as<std::string>() + "')", "",
                               KnobCheck::lenient));
        } catch (const ProtocolError& e) {
            throw StoreError(name_ +
                             ": the stored protocol no longer parses: " + e.what());
        }
        for (const pqxx::row& t : tx.exec_params(
                 "SELECT t.id, coalesce(t.uuid, ''), EXISTS (SELECT 1 FROM responses x "
                 "WHERE x.trial_id = t.id), t.block, coalesce(t.kind, t.task), "
                 "coalesce(t.staircase, ''), t.skipped FROM trials t WHERE "
                 "t.session_id = $1",
                 session_id)) {
            const int64_t id = t[0].as<int64_t>();
            c.trial_uuid[id] = t[1].as<std::string>();
            c.trial_block[id] = t[3].as<std::string>();
            c.trial_kind[id] = task_column(t[4].as<std::optional<std::string>>());
            c.trial_staircase[id] = t[5].as<std::string>();
            if (t[2].as<bool>()) c.answered.insert(id);
            if (t[6].as<int>() != 0) c.skipped.insert(id);
        }
        return c;
    });
    // Answers journaled here and not yet on the server: answered, and the slots a
    // finishing one skipped, skipped.
    for (const auto& [id, uuid] : cache.trial_uuid) {
        if (cache.answered.count(id)) continue;
        const std::optional<JournaledTrial> journaled =
            journal_ ? journal_->find(uuid) : std::nullopt;
        if (!journaled) continue;
        cache.answered.insert(id);
        if (journaled->outcome.finishes_staircase) skip_finished(cache, id);
    }
    return sessions_.emplace(session_id, std::move(cache)).first->second;
}

std::vector<int64_t> PostgresStore::skip_finished(SessionCache& cache, int64_t trial_id) {
    std::vector<int64_t> skipped;
    const std::string& block = cache.trial_block[trial_id];
    const std::string& staircase = cache.trial_staircase[trial_id];
    for (const auto& [id, uuid] : cache.trial_uuid)
        if (id != trial_id && cache.trial_block[id] == block &&
            cache.trial_staircase[id] == staircase && !cache.answered.count(id) &&
            cache.skipped.insert(id).second)
            skipped.push_back(id);
    return skipped;
}

int PostgresStore::begin_segment(int64_t session_id, const SessionEnvironment& env) {
    check_stimulus_values(env.stimuli);
    return guarded("starting a segment", [&] {
        pqxx::work tx(connection());
        const int segment = tx.exec_params1(
                                  "SELECT coalesce(max(segment), 0) + 1 FROM "
                                  "session_segments WHERE session_id = $1",
                                  session_id)[0]
                                .as<int>();
        insert_segment(tx, session_id, segment, env);
        tx.commit();
        return segment;
    });
}

int PostgresStore::resume_segment(int64_t session_id, const SessionEnvironment& env) {
    check_stimulus_values(env.stimuli);
    return guarded("starting a segment", [&] {
        pqxx::work tx(connection());
        const pqxx::result newest = tx.exec_params(
            "SELECT g.id, g.segment, EXISTS (SELECT 1 FROM trials t WHERE t.segment_id = "
            "g.id) "
            "FROM session_segments g WHERE g.session_id = $1 ORDER BY g.segment DESC "
            "LIMIT 1 "
            "FOR UPDATE OF g",
            session_id);
        int segment = 1;
        if (!newest.empty() && !newest[0][2].as<bool>()) {
            // Nothing was answered under the newest segment: replaced, not added to.
            segment = newest[0][1].as<int>();
            tx.exec_params("DELETE FROM session_segments WHERE id = $1",
                           newest[0][0].as<int64_t>());
            if (segment == 1) copy_environment_to_session_row(tx, session_id, env);
        } else if (!newest.empty()) {
            segment = newest[0][1].as<int>() + 1;
        }
        insert_segment(tx, session_id, segment, env);
        tx.commit();
        return segment;
    });
}

void PostgresStore::update_environment(int64_t session_id,
                                       const SessionEnvironment& env) {
    guarded("updating the environment", [&] {
        pqxx::work tx(connection());
        exec_with_environment(tx,
                              "UPDATE session_segments SET " +
                                  environment_assignments(true) +
                                  " WHERE id = (SELECT max(id) FROM session_segments "
                                  "WHERE session_id = $10)",
                              env, session_id);
        if (tx.exec_params1("SELECT count(*) FROM session_segments WHERE session_id = $1",
                            session_id)[0]
                .as<int64_t>() == 1)
            copy_environment_to_session_row(tx, session_id, env);
        tx.commit();
        return 0;
    });
}

namespace {
// decline_consent inside the caller's transaction, under the decline lock (one decline
// at a time compares the codes, so two processes never count one code twice).
bool add_declined_code(pqxx::work& tx, int64_t study_id, const std::string& code,
                       const std::string& page_uuid) {
    tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", kLockClass, kDeclineLock);
    std::vector<SaltedCode> held;
    for (const pqxx::row& r : tx.exec_params(
             "SELECT salt, code_hash FROM declined_codes WHERE study_id = $1", study_id))
        held.push_back({r[0].as<std::string>(), r[1].as<std::string>()});
    const std::optional<SaltedCode> found = find_salted_code(held, code);
    if (!found && held.size() >= static_cast<size_t>(kMaxDeclinedCodes)) return false;
    if (!page_uuid.empty())  // the page is this code's now (a UUID is one page's)
        tx.exec_params("UPDATE declined_codes SET page_uuid = NULL WHERE page_uuid = $1",
                       page_uuid);
    if (found) {
        if (!page_uuid.empty())
            tx.exec_params(
                "UPDATE declined_codes SET page_uuid = $1 WHERE salt = $2 AND "
                "code_hash = $3",
                page_uuid, found->salt, found->code_hash);
        return false;
    }
    const SaltedCode row = salted_code(code);
    tx.exec_params(
        "INSERT INTO declined_codes (study_id, salt, code_hash, page_uuid) "
        "VALUES ($1, $2, $3, $4)",
        study_id, row.salt, row.code_hash,
        page_uuid.empty() ? std::optional<std::string>() : page_uuid);
    return true;
}
}  // namespace

bool PostgresStore::decline_consent(int64_t study_id, const std::string& code,
                                    const std::string& page_uuid) {
    return guarded("counting a declined consent", [&] {
        pqxx::work tx(connection());
        const bool counted = add_declined_code(tx, study_id, code, page_uuid);
        tx.commit();
        return counted;
    });
}

bool PostgresStore::consent_declined(const std::string& page_uuid) {
    return guarded("finding a declined page", [&] {
        pqxx::nontransaction tx(connection());
        return tx
            .exec_params1(
                "SELECT EXISTS (SELECT 1 FROM declined_codes WHERE page_uuid = $1) "
                "OR EXISTS (SELECT 1 FROM declined_pages WHERE uuid = $1)",
                page_uuid)[0]
            .as<bool>();
    });
}

bool PostgresStore::forget_declined_session(int64_t session_id) {
    return guarded("forgetting a declined session", [&] {
        pqxx::work tx(connection());
        const pqxx::result found = tx.exec_params(
            "SELECT study_id, participant_id FROM sessions WHERE id = $1 AND consent_utc "
            "IS NULL "
            "AND NOT EXISTS (SELECT 1 FROM responses r WHERE r.session_id = sessions.id) "
            "FOR UPDATE",
            session_id);
        if (found.empty()) return false;
        const int64_t study_id = found[0][0].as<int64_t>();
        const int64_t participant_id = found[0][1].as<int64_t>();
        const std::string code =
            tx.exec_params1("SELECT code FROM participants WHERE id = $1",
                            participant_id)[0]
                .as<std::string>();
        tx.exec_params("DELETE FROM sessions WHERE id = $1", session_id);
        tx.exec_params(
            "DELETE FROM participants WHERE id = $1 AND NOT EXISTS "
            "(SELECT 1 FROM sessions WHERE participant_id = $1)",
            participant_id);
        add_declined_code(tx, study_id, code, "");
        tx.commit();
        return true;
    });
}

void PostgresStore::set_consent(int64_t session_id) {
    guarded("recording consent", [&] {
        pqxx::nontransaction tx(connection());
        tx.exec_params("UPDATE sessions SET consent_utc = $1 WHERE id = $2",
                       utc_now_iso8601(), session_id);
        tx.commit();
        return 0;
    });
}

bool PostgresStore::has_consent(int64_t session_id) {
    return guarded("reading consent", [&] {
        pqxx::nontransaction tx(connection());
        const pqxx::result r = tx.exec_params(
            "SELECT consent_utc IS NOT NULL FROM sessions WHERE id = $1", session_id);
        return !r.empty() && r[0][0].as<bool>();
    });
}

std::optional<std::string> PostgresStore::web_position(int64_t session_id) {
    return guarded("reading the page's position", [&]() -> std::optional<std::string> {
        pqxx::nontransaction tx(connection());
        const pqxx::result r =
            tx.exec_params("SELECT web_position FROM sessions WHERE id = $1", session_id);
        if (r.empty() || r[0][0].is_null()) return std::nullopt;
        return r[0][0].as<std::string>();
    });
}

void PostgresStore::set_web_position(int64_t session_id, const std::string& position) {
    guarded("storing the page's position", [&] {
        pqxx::nontransaction tx(connection());
        tx.exec_params("UPDATE sessions SET web_position = $1 WHERE id = $2", position,
                       session_id);
        tx.commit();
        return 0;
    });
}

// ---- [5] status, withdrawal, counts ---------------------------------------------------

void PostgresStore::set_status(int64_t session_id, const std::string& status,
                               bool ended) {
    try {
        guarded("setting the session status", [&] {
            pqxx::work tx(connection());
            const pqxx::result current = tx.exec_params(
                "SELECT status, uuid FROM sessions WHERE id = $1 FOR UPDATE", session_id);
            if (!current.empty())
                check_status_change(name_, current[0][1].as<std::string>(),
                                    current[0][0].as<std::string>(), status);
            if (ended)
                tx.exec_params(
                    "UPDATE sessions SET status = $1, ended_utc = $2 WHERE id = $3",
                    status, utc_now_iso8601(), session_id);
            else
                tx.exec_params(
                    "UPDATE sessions SET status = $1, ended_utc = NULL WHERE id = $2",
                    status, session_id);
            tx.commit();
            return 0;
        });
    } catch (const Unreachable&) {
        if (status != "paused") throw;
        // Left 'running' on the server; a resume treats both alike.
    }
}

bool PostgresStore::withdraw_participant(const std::string& code) {
    return guarded("withdrawing the participant", [&] {
        pqxx::work tx(connection());
        tx.exec_params("SELECT pg_advisory_xact_lock($1, $2)", kLockClass, kNumberLock);
        // Tombstones (withdrawal.h) in the same transaction as the delete.
        if (!tx.exec_params("SELECT 1 FROM participants WHERE code = $1", code).empty()) {
            const std::string now = utc_now_iso8601();
            std::vector<std::pair<std::string, std::string>> sessions;  // uuid, machine
            for (const pqxx::row& r : tx.exec_params(
                     "SELECT se.uuid, se.machine_id FROM sessions se JOIN "
                     "participants p ON p.id = se.participant_id WHERE p.code = $1",
                     code))
                sessions.emplace_back(r[0].as<std::string>(), r[1].as<std::string>());
            for (const auto& [uuid, machine] : sessions)
                tx.exec_params(
                    "INSERT INTO withdrawn_sessions (uuid, withdrawn_utc) VALUES "
                    "($1, $2) ON CONFLICT DO NOTHING",
                    uuid, now);
            for (const WithdrawnCode& c : code_tombstones(code, sessions, now))
                tx.exec_params(
                    "INSERT INTO withdrawn_codes (salt, code_hash, withdrawn_utc) "
                    "VALUES ($1, $2, $3) ON CONFLICT DO NOTHING",
                    c.salt, c.code_hash, c.withdrawn_utc);
        }
        tx.exec_params(
            "INSERT INTO retired_participant_numbers (number) SELECT number FROM "
            "participants WHERE code = $1 ON CONFLICT DO NOTHING",
            code);
        const pqxx::result gone =
            tx.exec_params("DELETE FROM participants WHERE code = $1", code);
        tx.commit();
        return gone.affected_rows() > 0;
    });
}

std::optional<ParticipantCounts> PostgresStore::participant_counts(
    const std::string& code) {
    return guarded("counting", [&]() -> std::optional<ParticipantCounts> {
        pqxx::work tx(connection());
        const pqxx::result r = tx.exec_params(
            "SELECT count(DISTINCT se.id), count(r.id) FROM participants p "
            "LEFT JOIN sessions se ON se.participant_id = p.id "
            "LEFT JOIN responses r ON r.session_id = se.id WHERE p.code = $1 GROUP BY "
            "p.id",
            code);
        if (r.empty()) return std::nullopt;
        return ParticipantCounts{r[0][0].as<int64_t>(), r[0][1].as<int64_t>()};
    });
}

int64_t PostgresStore::query_int(const std::string& sql) {
    return guarded("querying", [&] {
        pqxx::read_transaction tx(connection());
        const pqxx::result r = tx.exec_params(sql);
        return r.empty() || r[0][0].is_null() ? int64_t(0) : r[0][0].as<int64_t>();
    });
}

}  // namespace lucent::study
