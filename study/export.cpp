// CSV export and the analysis long table.
#include "study/export.h"

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "common/csv.h"
#include "common/number_text.h"
#include "common/output_file.h"
#include "study/observations.h"
#include "study/question_scales.h"
#include "study/schema.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/store_rules.h"
#include "study/withdrawal.h"

namespace lucent::study {
namespace {

Database open_read_only(const std::string& path) {
    check_database_file(path);
    Database db(path, SQLITE_OPEN_READONLY);
    if (db.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = 'responses'") == 0)
        throw StoreError(path + ": holds no study yet (run a session first)");
    return db;
}

// Parameters of every stimulus: stimulus key -> (name -> value).
std::map<std::string, std::map<std::string, std::string>> stimulus_parameters(
    Database& db) {
    std::map<std::string, std::map<std::string, std::string>> out;
    Statement s = db.prepare(
        "SELECT st.stimulus_key, p.name, p.value FROM stimulus_parameters p "
        "JOIN stimuli st ON st.id = p.stimulus_id");
    while (s.step()) out[s.text(0)][s.text(1)] = s.text(2);
    return out;
}

// Participants whose catch-trial failures exceed the protocol's allowance.
std::map<std::string, int> catch_failures(Database& db) {
    std::map<std::string, int> failed;
    Statement s = db.prepare(
        "SELECT p.code, count(DISTINCT t.id) FROM responses r "
        "JOIN trials t ON t.id = r.trial_id JOIN sessions s ON s.id = r.session_id "
        "JOIN participants p ON p.id = s.participant_id "
        "WHERE t.catch = 1 AND abs(r.rating - t.expected_rating) > coalesce(t.tolerance, "
        "0) "
        "GROUP BY p.code");
    while (s.step()) failed[s.text(0)] = static_cast<int>(s.integer(1));
    return failed;
}

int max_failed_catch(Database& db) {
    const std::optional<Protocol> protocol = stored_protocol(db);
    return protocol ? protocol->max_failed_catch : 0;
}

// The kind of trial `t` as SQL for this database's schema (schema.h).
std::string trial_kind(Database& db) {
    return trial_kind_sql(static_cast<int>(db.scalar_int("PRAGMA user_version")), "t");
}

// SQL condition on trials `t` keeping ratings only: forced choices (schema 6),
// adjustments and staircases (schema 7) are their own tables (export_choices,
// export_matches, export_staircase). Older databases hold nothing else.
std::string rating_trials(Database& db) {
    return " AND " + trial_kind(db) + " = 'rating' ";
}

std::string format_number(double v) {
    std::ostringstream out;
    out.precision(10);
    out << v;
    return out.str();
}

}  // namespace

// The protocol the database was made with; empty when absent or no longer parseable
// (a database from an older build whose keys this one does not know).
std::optional<Protocol> stored_protocol(Database& db) {
    Statement s = db.prepare("SELECT protocol_text, name FROM studies LIMIT 1");
    if (!s.step()) return std::nullopt;
    try {
        return parse_protocol(s.text(0), db.path() + " (stored protocol)", "",
                              KnobCheck::lenient);
    } catch (const ProtocolError&) {
        return std::nullopt;
    }
}

std::string declined_consent_figure(Database& db) {
    auto has_table = [&](const char* name) {
        Statement s = db.prepare("SELECT count(*) FROM sqlite_schema WHERE name = ?");
        s.bind(1, name);
        return s.step() && s.integer(0) > 0;
    };
    std::string out;
    if (has_table("declined_codes")) {
        const int64_t codes = db.scalar_int("SELECT count(*) FROM declined_codes");
        out = (codes >= kMaxDeclinedCodes ? "at least " : "") + std::to_string(codes) +
              (codes == 1 ? " participant code" : " participant codes") +
              " declined consent";
    }
    if (has_table("consent_declines")) {
        const int64_t pages =
            db.scalar_int("SELECT coalesce(sum(declined), 0) FROM consent_declines");
        if (pages > 0 || out.empty())
            out += (out.empty() ? "" : ", and ") + std::to_string(pages) +
                   (pages == 1 ? " consent decline" : " consent declines") +
                   " counted per page before schema 9 (page loads, not people)";
    }
    return out;
}

SessionSelection select_sessions(Database& db, const std::string& db_path,
                                 const std::string& sessions, bool exclude_failed_catch) {
    SessionSelection out;
    // Which sessions are read: never a withdrawn one (a tombstone's UUID; its rows are
    // normally gone already), and with "completed" only completed ones.
    std::set<std::string> withdrawn;
    if (db.scalar_int(
            "SELECT count(*) FROM sqlite_schema WHERE name = 'withdrawn_sessions'") > 0) {
        Statement w = db.prepare("SELECT uuid FROM withdrawn_sessions");
        while (w.step()) withdrawn.insert(w.text(0));
    }
    out.left_out.withdrawn = static_cast<int>(withdrawn.size());
    out.total = out.left_out.withdrawn;
    {
        Statement q = db.prepare(
            "SELECT se.id, se.uuid, se.status, p.code FROM sessions se "
            "JOIN participants p ON p.id = se.participant_id ORDER BY se.id");
        while (q.step()) {
            if (withdrawn.count(q.text(1))) continue;  // counted with the tombstones
            ++out.total;
            const std::string status = q.text(2);
            if (sessions == "completed" && status != "completed") {
                ++out.left_out.incomplete;
                ++out.left_out.incomplete_by_status[status];
                continue;
            }
            out.taken[q.integer(0)] = q.text(3);
        }
    }

    // Catch trials failed in the sessions taken, per participant.
    if (exclude_failed_catch) {
        const int allowed = max_failed_catch(db);
        std::map<std::string, int> failed;
        Statement f = db.prepare(
            "SELECT r.session_id, count(DISTINCT t.id) FROM responses r "
            "JOIN trials t ON t.id = r.trial_id "
            "WHERE t.catch = 1 AND abs(r.rating - t.expected_rating) > "
            "coalesce(t.tolerance, 0) "
            "GROUP BY r.session_id");
        while (f.step()) {
            const auto it = out.taken.find(f.integer(0));
            if (it != out.taken.end())
                failed[it->second] += static_cast<int>(f.integer(1));
        }
        for (const auto& [participant, n] : failed)
            if (n > allowed) {
                out.excluded.insert(participant);
                out.excluded_participants.push_back(
                    participant + " (" + std::to_string(n) + " catch trials failed)");
            }
        for (const auto& [id, participant] : out.taken)
            if (out.excluded.count(participant)) ++out.left_out.failed_catch;
    }
    out.analysed = static_cast<int>(out.taken.size()) - out.left_out.failed_catch;
    {
        const SessionsLeftOut& l = out.left_out;
        std::string note = db_path + ": " + std::to_string(out.analysed) + " of " +
                           std::to_string(out.total) + " sessions analysed (" +
                           (sessions == "completed"
                                ? "completed sessions only, the analysis plan's default"
                                : "sessions of every status, as the analysis plan says") +
                           "); left out: " + std::to_string(l.incomplete) + " incomplete";
        if (!l.incomplete_by_status.empty()) {
            note += " (";
            bool first = true;
            for (const auto& [status, n] : l.incomplete_by_status) {
                note += (first ? "" : ", ") + std::to_string(n) + " " + status;
                first = false;
            }
            note += ")";
        }
        note += ", " + std::to_string(l.failed_catch) + " failed catch trials, " +
                std::to_string(l.withdrawn) + " withdrawn";
        if (const std::string declined = declined_consent_figure(db); !declined.empty())
            note += "; " + declined;
        out.note = note;
    }

    return out;
}

int export_csv(const std::string& db_path, ExportFormat format, std::ostream& out,
               std::vector<std::string>* notes) {
    Database db = open_read_only(db_path);
    const auto params = stimulus_parameters(db);
    const auto resolved = read_resolved_stimuli(db);
    std::set<std::string> names;
    for (const auto& [stimulus, values] : params)
        for (const auto& [name, value] : values) names.insert(name);
    for (const auto& [stimulus, r] : resolved)
        for (const auto& [name, value] : r.values) names.insert(name);
    const auto failed = catch_failures(db);
    int rows = 0;

    if (format == ExportFormat::Long) {
        out << "participant,session,trial_position,block,stimulus,technique,mesh";
        for (const std::string& n : names) out << "," << common::csv_field(n);
        out << ",mesh_hash,stimulus_source,image_file,image_hash,renderer_version,"
               "renderer_build";
        out << ",question,rating,rt_ms,changes,practice,catch,expected_rating,catch_"
               "passed\n";
        // What the trial's segment showed (schema 3); NULL for older ratings.
        const bool has_provenance = db.scalar_int("PRAGMA user_version") >= 3;
        Statement s = db.prepare(
            std::string(
                "SELECT p.code, se.uuid, t.position, t.block, st.stimulus_key, "
                "st.technique, st.mesh, r.question, r.rating, r.rt_ms, r.changes, "
                "t.practice, t.catch, t.expected_rating, coalesce(t.tolerance, 0), ") +
            (has_provenance ? "shown.source, shown.file, shown.content_hash, "
                              "shown.software_version, shown.build_hash "
                            : "NULL, NULL, NULL, NULL, NULL ") +
            "FROM responses r "
            "JOIN trials t ON t.id = r.trial_id JOIN sessions se ON se.id = r.session_id "
            "JOIN participants p ON p.id = se.participant_id "
            "JOIN stimuli st ON st.id = t.stimulus_id " +
            (has_provenance ? "LEFT JOIN segment_stimuli shown ON shown.segment_id = "
                              "t.segment_id AND shown.stimulus_id = t.stimulus_id "
                            : "") +
            "WHERE 1" + rating_trials(db) + "ORDER BY p.code, se.id, t.position, r.id");
        int without_provenance = 0;
        while (s.step()) {
            const auto known = s.is_null(15) ? resolved.end() : resolved.find(s.text(4));
            const bool recorded = known != resolved.end();
            without_provenance += recorded ? 0 : 1;
            for (int c = 0; c < 6; ++c)
                out << (c ? "," : "") << common::csv_field(s.text(c));
            out << "," << common::csv_field(recorded ? known->second.mesh : s.text(6));
            const auto it = params.find(s.text(4));
            for (const std::string& n : names) {
                std::string v;
                if (recorded) {
                    if (known->second.values.count(n)) v = known->second.values.at(n);
                } else if (it != params.end() && it->second.count(n)) {
                    v = it->second.at(n);
                }
                out << "," << common::csv_field(v);
            }
            out << "," << common::csv_field(recorded ? known->second.mesh_hash : "");
            for (int c = 15; c < 20; ++c) out << "," << common::csv_field(s.text(c));
            const bool is_catch = s.integer(12) != 0;
            std::string passed;
            if (is_catch)
                passed =
                    std::abs(s.integer(8) - s.integer(13)) <= s.integer(14) ? "1" : "0";
            out << "," << common::csv_field(s.text(7)) << "," << s.integer(8) << ","
                << format_number(s.real(9)) << "," << s.integer(10) << ","
                << s.integer(11) << "," << s.integer(12) << ","
                << (is_catch ? s.text(13) : "") << "," << passed << "\n";
            ++rows;
        }
        if (notes && without_provenance > 0)
            notes->push_back(
                db_path + ": " + std::to_string(without_provenance) + " of " +
                std::to_string(rows) +
                " ratings were recorded without provenance (a database written before "
                "schema 3): only the protocol's own parameter values are known for them; "
                "defaults, mesh_hash, stimulus_source, image and renderer cells are "
                "empty");
        return rows;
    }

    // Wide: one row per participant, one column per (stimulus, question) of the rated
    // (non-practice, non-catch) trials; repeated ratings are averaged.
    std::vector<std::string> columns;
    std::set<std::string> seen;
    std::map<std::string, std::map<std::string, std::pair<double, int>>> cells;
    std::map<std::string, int> sessions;
    {
        Statement s = db.prepare(
            "SELECT p.code, st.stimulus_key, r.question, r.rating FROM responses r "
            "JOIN trials t ON t.id = r.trial_id JOIN sessions se ON se.id = r.session_id "
            "JOIN participants p ON p.id = se.participant_id "
            "JOIN stimuli st ON st.id = t.stimulus_id "
            "WHERE t.practice = 0 AND t.catch = 0" +
            rating_trials(db) + "ORDER BY st.id, r.id");
        while (s.step()) {
            const std::string column = s.text(1) + "." + s.text(2);
            if (seen.insert(column).second) columns.push_back(column);
            auto& cell = cells[s.text(0)][column];
            cell.first += static_cast<double>(s.integer(3));
            cell.second += 1;
        }
        Statement c = db.prepare(
            "SELECT p.code, count(s.id) FROM participants p "
            "LEFT JOIN sessions s ON s.participant_id = p.id GROUP BY p.code ORDER BY "
            "p.code");
        while (c.step()) sessions[c.text(0)] = static_cast<int>(c.integer(1));
    }
    out << "participant,sessions,catch_failed";
    for (const std::string& c : columns) out << "," << common::csv_field(c);
    out << "\n";
    for (const auto& [participant, n_sessions] : sessions) {
        const auto f = failed.find(participant);
        out << common::csv_field(participant) << "," << n_sessions << ","
            << (f == failed.end() ? 0 : f->second);
        const auto& row = cells[participant];
        for (const std::string& c : columns) {
            const auto it = row.find(c);
            out << ",";
            if (it != row.end())
                out << format_number(it->second.first / it->second.second);
        }
        out << "\n";
        ++rows;
    }
    return rows;
}

namespace {

// A measure or value as the shortest exact text, or empty when it was not recorded.
std::string optional_text(const std::map<std::string, double>& measures,
                          const std::string& name) {
    const auto it = measures.find(name);
    return it == measures.end() ? std::string() : common::shortest_text(it->second);
}

std::string optional_text(const std::optional<double>& v) {
    return v ? common::shortest_text(*v) : std::string();
}

}  // namespace

ChoiceExport export_choices(const std::string& db_path, std::ostream& out,
                            const ChoiceExportOptions& options) {
    const StudyObservations read = read_observations(
        db_path, {.analysis = options.analysis, .sessions = options.sessions});
    ChoiceExport result;
    out << "participant,session,trial,block,task,question,practice,catch,expected,"
           "shown_1,shown_2,shown_3,shown_4,value_1,value_2,value_3,value_4,choice,"
           "rt_ms\n";
    if (options.analysis) {
        result.excluded_participants = read.selection.excluded_participants;
        result.notes.push_back(read.selection.note);
    }
    for (const common::Observation& row : read.table.rows) {
        const std::optional<Task> task = parse_task(row.kind);
        if (!task || !is_scaling_task(*task)) continue;
        out << common::csv_field(row.participant) << "," << common::csv_field(row.session)
            << "," << row.trial << "," << common::csv_field(row.block) << ","
            << common::csv_field(row.kind) << "," << common::csv_field(row.question)
            << "," << (row.practice ? 1 : 0) << "," << (row.is_catch ? 1 : 0) << ","
            << (row.expected ? std::to_string(*row.expected) : std::string());
        for (size_t k = 0; k < 4; ++k)
            out << "," << common::csv_field(k < row.shown.size() ? row.shown[k] : "");
        for (size_t k = 0; k < 4; ++k)
            out << "," << optional_text(row.measures, "value_" + std::to_string(k + 1));
        out << "," << static_cast<int>(row.response.value_or(0)) << ","
            << format_number(row.rt_ms) << "\n";
        ++result.rows;
    }
    return result;
}

namespace {

// Milliseconds from `from_ns` to `to_ns`, as the shortest exact text.
std::string ms_between(int64_t from_ns, int64_t to_ns) {
    return common::shortest_text(static_cast<double>(to_ns - from_ns) / 1e6);
}

std::string optional_number(Statement& s, int col) {
    return s.is_null(col) ? std::string() : common::shortest_text(s.real(col));
}

// The sessions an export of adjustments or staircases reads: every one not withdrawn.
std::map<std::int64_t, std::string> readable_sessions(Database& db,
                                                      const std::string& db_path) {
    return select_sessions(db, db_path, "all", false).taken;
}

}  // namespace

int export_adjustments(const std::string& db_path, std::ostream& out) {
    Database db = open_read_only(db_path);
    out << "participant,session,trial,block,target,start_value,step,value,t_ms,input\n";
    if (db.scalar_int("PRAGMA user_version") < 7) return 0;  // none recorded before
    const auto taken = readable_sessions(db, db_path);
    Statement s = db.prepare(
        "SELECT p.code, se.uuid, t.position, t.block, st.stimulus_key, t.start_value, "
        "a.step, a.value, a.t_ns, t.onset_ns, a.input, se.id FROM adjustments a "
        "JOIN trials t ON t.id = a.trial_id JOIN sessions se ON se.id = t.session_id "
        "JOIN participants p ON p.id = se.participant_id "
        "JOIN stimuli st ON st.id = t.stimulus_id "
        "ORDER BY p.code, se.id, t.position, a.step");
    int rows = 0;
    while (s.step()) {
        if (!taken.count(s.integer(11))) continue;  // withdrawn
        out << common::csv_field(s.text(0)) << "," << common::csv_field(s.text(1)) << ","
            << s.integer(2) << "," << common::csv_field(s.text(3)) << ","
            << common::csv_field(s.text(4)) << "," << optional_number(s, 5) << ","
            << s.integer(6) << "," << common::shortest_text(s.real(7)) << ","
            << (s.is_null(9) ? std::string() : ms_between(s.integer(9), s.integer(8)))
            << "," << common::csv_field(s.text(10)) << "\n";
        ++rows;
    }
    return rows;
}

namespace {

// Every answer of every session not withdrawn, practice included: what the per-kind
// exports below write, each from the rows its kinds are analysed as.
StudyObservations exported_observations(const std::string& db_path) {
    return read_observations(db_path, {.analysis = false});
}

}  // namespace

int export_matches(const std::string& db_path, std::ostream& out) {
    const StudyObservations read = exported_observations(db_path);
    out << "participant,session,trial,block,practice,target,match_knob,start_value,"
           "final_value,adjustments,total_ms\n";
    auto knob_of = [&](const std::string& block) {
        const Block* b = read.protocol ? read.protocol->find_block(block) : nullptr;
        return b ? b->knob : std::string();
    };
    int rows = 0;
    for (const common::Observation& row : read.table.rows) {
        if (row.analysed_as != "matches") continue;
        out << common::csv_field(row.participant) << "," << common::csv_field(row.session)
            << "," << row.trial << "," << common::csv_field(row.block) << ","
            << (row.practice ? 1 : 0) << ","
            << common::csv_field(row.shown.empty() ? "" : row.shown.front()) << ","
            << common::csv_field(knob_of(row.block)) << ","
            << optional_text(row.measures, "start_value") << ","
            << optional_text(row.response) << ","
            << optional_text(row.measures, "adjustments") << ","
            << common::shortest_text(row.rt_ms) << "\n";
        ++rows;
    }
    return rows;
}

int export_staircase(const std::string& db_path, std::ostream& out) {
    const StudyObservations read = exported_observations(db_path);
    out << "participant,session,trial,block,standard,staircase,intensity,expected,"
           "choice,correct,rt_ms\n";
    int rows = 0;
    for (const common::Observation& row : read.table.rows) {
        if (row.analysed_as != "thresholds") continue;
        const std::string choice =
            row.response ? std::to_string(static_cast<long long>(*row.response)) : "";
        out << common::csv_field(row.participant) << "," << common::csv_field(row.session)
            << "," << row.trial << "," << common::csv_field(row.block) << ","
            << common::csv_field(row.shown.empty() ? "" : row.shown.front()) << ","
            << common::csv_field(row.procedure) << ","
            << optional_text(row.measures, "intensity") << ","
            << (row.expected ? std::to_string(*row.expected) : std::string()) << ","
            << choice << ","
            << (row.expected && row.response
                    ? (static_cast<long long>(*row.response) == *row.expected ? "1" : "0")
                    : "")
            << "," << common::shortest_text(row.rt_ms) << "\n";
        ++rows;
    }
    return rows;
}

ExportFileResult export_file(const std::string& db_path, const std::string& format,
                             const std::string& out_path, bool force) {
    ExportFileResult result;
    try {
        common::check_output_file(out_path, {db_path}, force);
        common::write_file_atomically(out_path, force, [&](std::ostream& out) {
            if (format == "analysis" || format == "observations") {
                check_stored_ratings(db_path);  // no impossible rating enters an analysis
                const StudyObservations read = read_observations(db_path);
                if (format == "analysis") {
                    result.rows = write_factor_ratings_csv(read.table, out);
                } else {
                    common::write_observation_csv(out, read.table);
                    result.rows = static_cast<int>(read.table.rows.size());
                }
                result.excluded_participants = read.selection.excluded_participants;
                result.notes.push_back(read.selection.note);
            } else if (format == "choices" || format == "choice-analysis") {
                const bool analysis = format == "choice-analysis";
                const ChoiceExport choices =
                    export_choices(db_path, out, {.analysis = analysis});
                result.rows = choices.rows;
                result.excluded_participants = choices.excluded_participants;
                result.notes = choices.notes;
            } else if (format == "adjustments") {
                result.rows = export_adjustments(db_path, out);
            } else if (format == "matches") {
                result.rows = export_matches(db_path, out);
            } else if (format == "staircase") {
                result.rows = export_staircase(db_path, out);
            } else if (format == "long" || format == "wide") {
                result.rows = export_csv(
                    db_path, format == "long" ? ExportFormat::Long : ExportFormat::Wide,
                    out, &result.notes);
            } else {
                throw StoreError(
                    "export: unknown format '" + format +
                    "' (valid: long, wide, analysis, choices, choice-analysis, "
                    "adjustments, matches, staircase, observations)");
            }
        });
    } catch (const common::OutputError& e) {
        throw StoreError(e.what());
    }
    return result;
}

int write_factor_ratings_csv(const common::ObservationTable& table, std::ostream& out) {
    out << "participant,stimulus,factor,level,question,rating\n";
    const std::vector<common::FactorRating> rows = common::factor_ratings(table);
    for (const common::FactorRating& r : rows)
        out << common::csv_field(r.observation->participant) << ","
            << common::csv_field(r.observation->shown.front()) << ","
            << common::csv_field(*r.factor) << "," << common::csv_field(*r.level) << ","
            << common::csv_field(r.observation->question) << ","
            << static_cast<int>(*r.observation->response) << "\n";
    return static_cast<int>(rows.size());
}

}  // namespace lucent::study
