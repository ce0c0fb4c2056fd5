// The schema's text, one migration step at a time.
#include "study/schema.h"

#include <algorithm>
#include <iterator>

namespace lucent::study {
namespace {

// Migration i (1-based) brings user_version from i-1 to i. Never edit a released step:
// add a new one.
const char* const kMigrations[] = {
    // 1: the core tables.
    R"sql(
CREATE TABLE studies (
    id INTEGER PRIMARY KEY,
    name TEXT NOT NULL,
    protocol_text TEXT NOT NULL,
    protocol_hash TEXT NOT NULL UNIQUE,
    created_utc TEXT NOT NULL);
CREATE TABLE stimuli (
    id INTEGER PRIMARY KEY,
    study_id INTEGER NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    stimulus_key TEXT NOT NULL,
    technique TEXT NOT NULL,
    mesh TEXT NOT NULL,
    image TEXT NOT NULL,
    varies TEXT NOT NULL,
    UNIQUE (study_id, stimulus_key));
CREATE TABLE stimulus_parameters (
    stimulus_id INTEGER NOT NULL REFERENCES stimuli(id) ON DELETE CASCADE,
    name TEXT NOT NULL,
    value TEXT NOT NULL,
    PRIMARY KEY (stimulus_id, name));
CREATE TABLE participants (
    id INTEGER PRIMARY KEY,
    study_id INTEGER NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    code TEXT NOT NULL UNIQUE,
    number INTEGER NOT NULL,
    created_utc TEXT NOT NULL);
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY,
    uuid TEXT NOT NULL UNIQUE,
    study_id INTEGER NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    participant_id INTEGER NOT NULL REFERENCES participants(id) ON DELETE CASCADE,
    machine_id TEXT NOT NULL,
    seed TEXT NOT NULL,
    cell INTEGER NOT NULL,
    block_order TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('running', 'paused', 'completed', 'aborted')),
    started_utc TEXT NOT NULL,
    ended_utc TEXT,
    consent_utc TEXT,
    software_version TEXT NOT NULL,
    build_hash TEXT NOT NULL,
    gl_vendor TEXT,
    gl_renderer TEXT,
    display_mode TEXT,
    display_refresh_hz REAL,
    measured_refresh_hz REAL);
CREATE TABLE trials (
    id INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
    position INTEGER NOT NULL,
    block TEXT NOT NULL,
    stimulus_id INTEGER NOT NULL REFERENCES stimuli(id),
    practice INTEGER NOT NULL CHECK (practice IN (0, 1)),
    catch INTEGER NOT NULL CHECK (catch IN (0, 1)),
    catch_id TEXT,
    prompt TEXT,
    expected_rating INTEGER,
    tolerance INTEGER,
    break_before INTEGER NOT NULL CHECK (break_before IN (0, 1)),
    onset_ns INTEGER,
    confirm_ns INTEGER,
    answered_utc TEXT,
    UNIQUE (session_id, position));
CREATE TABLE responses (
    id INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
    trial_id INTEGER NOT NULL REFERENCES trials(id) ON DELETE CASCADE,
    question TEXT NOT NULL,
    rating INTEGER NOT NULL CHECK (rating BETWEEN 1 AND 7),
    rt_ms REAL NOT NULL CHECK (rt_ms >= 0),
    changes INTEGER NOT NULL CHECK (changes >= 0),
    first_choice_ns INTEGER NOT NULL,
    final_choice_ns INTEGER NOT NULL,
    UNIQUE (trial_id, question));
CREATE INDEX responses_by_session ON responses(session_id);
CREATE INDEX trials_by_session ON trials(session_id);
)sql",
    // 2: frame timing (why a refresh is unknown; dropped frames per trial).
    R"sql(
ALTER TABLE sessions ADD COLUMN refresh_note TEXT;
ALTER TABLE trials ADD COLUMN dropped_frames INTEGER;
)sql",
    // 3: provenance: every resolved value per stimulus, one environment row per session
    // segment (start, each resume) and where each picture of a segment came from.
    // Existing sessions get their first segment from the session row; trials answered
    // before keep segment_id NULL (nothing was recorded about what they showed).
    R"sql(
ALTER TABLE stimuli ADD COLUMN resolved_mesh TEXT;
ALTER TABLE stimuli ADD COLUMN mesh_hash TEXT;
CREATE TABLE stimulus_values (
    stimulus_id INTEGER NOT NULL REFERENCES stimuli(id) ON DELETE CASCADE,
    name TEXT NOT NULL,
    value TEXT NOT NULL,
    PRIMARY KEY (stimulus_id, name));
CREATE TABLE session_segments (
    id INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
    segment INTEGER NOT NULL,
    started_utc TEXT NOT NULL,
    machine_id TEXT NOT NULL,
    software_version TEXT NOT NULL,
    build_hash TEXT NOT NULL,
    gl_vendor TEXT,
    gl_renderer TEXT,
    display_mode TEXT,
    display_refresh_hz REAL,
    measured_refresh_hz REAL,
    refresh_note TEXT,
    stimulus_source TEXT CHECK (stimulus_source IN ('live', 'images', 'image', 'mixed')),
    UNIQUE (session_id, segment));
INSERT INTO session_segments (session_id, segment, started_utc, machine_id,
    software_version, build_hash, gl_vendor, gl_renderer, display_mode, display_refresh_hz,
    measured_refresh_hz, refresh_note)
SELECT id, 1, started_utc, machine_id, software_version, build_hash, gl_vendor,
    gl_renderer, display_mode, display_refresh_hz, measured_refresh_hz, refresh_note
FROM sessions;
CREATE TABLE segment_stimuli (
    segment_id INTEGER NOT NULL REFERENCES session_segments(id) ON DELETE CASCADE,
    stimulus_id INTEGER NOT NULL REFERENCES stimuli(id) ON DELETE CASCADE,
    source TEXT NOT NULL CHECK (source IN ('live', 'images', 'image')),
    file TEXT,
    content_hash TEXT,
    software_version TEXT NOT NULL,
    build_hash TEXT NOT NULL,
    PRIMARY KEY (segment_id, stimulus_id));
ALTER TABLE trials ADD COLUMN segment_id INTEGER REFERENCES session_segments(id);
CREATE INDEX segments_by_session ON session_segments(session_id);
-- Enrolment numbers of withdrawn participants (the number only, nothing personal): a
-- number, and with it a Latin-square row, is never handed out twice.
CREATE TABLE retired_participant_numbers (number INTEGER PRIMARY KEY);
)sql",
    // 4: a UUID per planned trial, so a station's journal can resend a trial to a server
    // idempotently and a merge can tell one trial from another. Earlier trials keep NULL.
    R"sql(
ALTER TABLE trials ADD COLUMN uuid TEXT;
CREATE UNIQUE INDEX trials_by_uuid ON trials(uuid);
)sql",
    // 5: withdrawals that survive merges, imports and syncs (tombstones: the withdrawn
    // sessions' UUIDs, and each (code, machine) as a salted SHA-256 so the code itself is
    // gone); how a session's counterbalancing cell was allocated; declined consents as
    // an anonymous count per study (nothing else of a decline is kept).
    R"sql(
CREATE TABLE withdrawn_sessions (
    uuid TEXT PRIMARY KEY,
    withdrawn_utc TEXT NOT NULL);
CREATE TABLE withdrawn_codes (
    salt TEXT NOT NULL,
    code_hash TEXT NOT NULL,
    withdrawn_utc TEXT NOT NULL,
    PRIMARY KEY (salt, code_hash));
ALTER TABLE sessions ADD COLUMN allocation TEXT;
CREATE TABLE consent_declines (
    study_id INTEGER NOT NULL PRIMARY KEY REFERENCES studies(id) ON DELETE CASCADE,
    declined INTEGER NOT NULL CHECK (declined >= 0));
)sql",
    // 6: forced-choice trials (issue 30): the block's task, and the stimuli a pair,
    // triad or quadruple shows in screen order (stimulus keys, space-separated;
    // trials.stimulus_id is the first). The choice itself is a response to the block's
    // question with rating 1 or 2, so copies, merges and withdrawals carry it as they
    // carry ratings. Earlier trials keep NULL: ratings.
    R"sql(
ALTER TABLE trials ADD COLUMN task TEXT CHECK (task IN ('rating', 'pair', 'triad', 'quadruple'));
ALTER TABLE trials ADD COLUMN shown TEXT;
)sql",
    // 7: adjustment and staircase trials (issue 31). trials.kind is the trial's kind,
    // authoritative from schema 7 on: trials.task's CHECK knows only the first four, and
    // SQLite cannot widen a CHECK without rebuilding the table, which under enforced
    // foreign keys would cascade-delete every response. So writers keep writing task for
    // rating, pair, triad and quadruple trials (older readers see them as before) and
    // NULL for adjust and staircase trials; every reader reads kind.
    // Adjust trials: the planned start_value and, answered, the confirmed final_value
    // (the response is the block's question with rating 1), each change of the knob in
    // adjustments. Staircase slots: the procedure (staircase, "<standard>/<procedure>"),
    // the delta shown once answered (intensity; the response is the place chosen), and
    // skipped = 1 for a slot left unanswered because its procedure had finished.
    R"sql(
ALTER TABLE trials ADD COLUMN kind TEXT CHECK (kind IN ('rating', 'pair', 'triad', 'quadruple', 'adjust', 'staircase'));
UPDATE trials SET kind = coalesce(task, 'rating');
ALTER TABLE trials ADD COLUMN start_value REAL;
ALTER TABLE trials ADD COLUMN final_value REAL;
ALTER TABLE trials ADD COLUMN staircase TEXT;
ALTER TABLE trials ADD COLUMN intensity REAL;
ALTER TABLE trials ADD COLUMN skipped INTEGER NOT NULL DEFAULT 0 CHECK (skipped IN (0, 1));
CREATE TABLE adjustments (
    trial_id INTEGER NOT NULL REFERENCES trials(id) ON DELETE CASCADE,
    step INTEGER NOT NULL CHECK (step >= 1),
    value REAL NOT NULL,
    t_ns INTEGER NOT NULL,
    input TEXT NOT NULL CHECK (input IN ('key', 'fine_key', 'wheel', 'drag')),
    PRIMARY KEY (trial_id, step));
)sql",
    // 8: several serve processes on one database (issue 32). sessions.web_position:
    // where a browser's page stands (the screen it shows, that screen's view number, the
    // page-clock time it began), one line the server writes after each action, so any
    // process continues the page where another left it; NULL for lab sessions.
    // declined_pages: the UUIDs a serve process drew for pages whose person declined
    // consent (random, linked to nothing of them: the code is never stored), so a
    // decline sent twice counts once and its page stays declined.
    R"sql(
ALTER TABLE sessions ADD COLUMN web_position TEXT;
CREATE TABLE declined_pages (uuid TEXT PRIMARY KEY);
)sql",
    // 9: declined consents per participant code (issue 44). consent_declines and
    // declined_pages counted a page that declined, so a script reloading and declining
    // counted each time, and one person declining twice counted twice. declined_codes:
    // one row per code that declined, the code kept as withdrawn_codes keep one (a
    // random salt per row and SHA-256, withdrawal.h), page_uuid the newest page of that
    // code that declined (NULL for a lab station), so that page stays declined. At most
    // kMaxDeclinedCodes rows per study (withdrawal.h). The older tables are kept as they
    // were, no longer written: their count is reported beside, as page declines before
    // schema 9, and pages they hold stay declined.
    R"sql(
CREATE TABLE declined_codes (
    study_id INTEGER NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    salt TEXT NOT NULL,
    code_hash TEXT NOT NULL,
    page_uuid TEXT UNIQUE,
    PRIMARY KEY (salt, code_hash));
CREATE INDEX declined_codes_by_study ON declined_codes(study_id);
)sql"
    // Also in 9: provenance of the pictures a study shows beyond its stimuli (an adjust
    // series' steps, a staircase's ladder: `lucent serve` serves each as a picture of
    // its own). One row per picture of each distinct set of files a study was served
    // from, keyed by the set's hash; a segment names its set (series_set, NULL when it
    // showed none), so rows grow with the folders used, not with the sessions.
    R"sql(
CREATE TABLE series_pictures (
    study_id INTEGER NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    set_hash TEXT NOT NULL,
    picture TEXT NOT NULL,
    file TEXT NOT NULL,
    content_hash TEXT NOT NULL,
    software_version TEXT NOT NULL,
    build_hash TEXT NOT NULL,
    PRIMARY KEY (study_id, set_hash, picture));
ALTER TABLE session_segments ADD COLUMN series_set TEXT;
)sql",
    // 10: trial kinds are a registry (study/trials/), so trials.kind may hold any
    // registered kind's name: its CHECK of the six built-in names goes, and the store's
    // rules (a kind this build does not know is refused on reading) guard it instead.
    // SQLite cannot drop a CHECK with ALTER TABLE; it documents this edit of the
    // table's SQL for removing one (lang_altertable.html, "Making Other Kinds Of Table
    // Schema Changes"): no row changes, and migrate() bumps schema_version so every
    // connection reads the new SQL. PostgreSQL drops the constraint by name.
    R"sql(
PRAGMA writable_schema = ON;
UPDATE sqlite_schema SET sql = replace(sql, ', kind TEXT CHECK (kind IN (''rating'', ''pair'', ''triad'', ''quadruple'', ''adjust'', ''staircase''))', ', kind TEXT') WHERE type = 'table' AND name = 'trials';
PRAGMA writable_schema = OFF;
)sql",
};
static_assert(std::size(kMigrations) == kSchemaVersion);

}  // namespace

const std::vector<std::string>& schema_migrations() {
    static const std::vector<std::string> steps(std::begin(kMigrations),
                                                std::end(kMigrations));
    return steps;
}

std::string trial_kind_sql(int version, const std::string& alias) {
    if (version >= 7) return "coalesce(" + alias + ".kind, " + alias + ".task, 'rating')";
    if (version >= 6) return "coalesce(" + alias + ".task, 'rating')";
    return "'rating'";
}

std::string open_trial_sql(const std::string& alias) {
    return alias +
           ".skipped = 0 AND NOT EXISTS (SELECT 1 FROM responses r WHERE r.trial_id = " +
           alias + ".id)";
}

std::string online_cell_counts_sql(bool postgres) {
    const std::string latest = postgres ? "greatest" : "max";
    const std::string study = postgres ? "$1" : "?1", since = postgres ? "$2" : "?2";
    return "SELECT s.cell, count(*) FROM sessions s WHERE s.study_id = " + study +
           " AND (s.status = 'completed' OR (s.status IN ('running', 'paused') AND " +
           latest +
           "(s.started_utc, coalesce((SELECT max(g.started_utc) FROM session_segments g "
           "WHERE "
           "g.session_id = s.id), ''), coalesce((SELECT max(t.answered_utc) FROM trials "
           "t "
           "WHERE t.session_id = s.id), '')) >= " +
           since + ")) GROUP BY s.cell";
}

namespace {
// Parameter `n`: SQLite's positional "?" or PostgreSQL's "$n".
std::string parameter(bool postgres, int n) {
    if (!postgres) return "?";
    std::string out = "$";  // appended to: GCC 12's -Wrestrict misfires on "$" + ...
    return out += std::to_string(n);
}
}  // namespace

std::string environment_values(bool postgres, int first) {
    std::string out;
    for (int i = 0; i < kEnvironmentColumnCount; ++i) {
        if (i > 0) out += ", ";
        out += parameter(postgres, first + i);
    }
    return out;
}

std::string environment_assignments(bool postgres) {
    std::string out;
    const std::string columns = kEnvironmentColumns;
    int n = 1;
    for (size_t start = 0; start < columns.size(); ++n) {
        const size_t end = std::min(columns.find(", ", start), columns.size());
        if (!out.empty()) out += ", ";
        out += columns.substr(start, end - start) + " = " + parameter(postgres, n);
        start = end + 2;
    }
    return out;
}

}  // namespace lucent::study
