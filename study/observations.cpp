#include "study/observations.h"

#include <map>
#include <sstream>
#include <vector>

#include "common/number_text.h"
#include "study/schema.h"
#include "study/sqlite/database.h"
#include "study/sqlite/database_file.h"
#include "study/store_rules.h"

namespace lucent::study {
namespace {

// A stimulus as the analysis sees it: its technique, the factors it was designed to
// vary (empty: every parameter) and its parameters.
struct StoredStimulus {
    std::string technique;
    std::vector<std::string> varies;
    std::map<std::string, std::string> parameters;
};

std::map<std::string, StoredStimulus> stored_stimuli(Database& db) {
    std::map<std::string, StoredStimulus> out;
    {
        Statement s = db.prepare("SELECT stimulus_key, technique, varies FROM stimuli");
        while (s.step()) {
            StoredStimulus& st = out[s.text(0)];
            st.technique = s.text(1);
            std::istringstream words(s.text(2));
            for (std::string w; words >> w;) st.varies.push_back(w);
        }
    }
    Statement s = db.prepare(
        "SELECT st.stimulus_key, p.name, p.value FROM stimulus_parameters p "
        "JOIN stimuli st ON st.id = p.stimulus_id");
    while (s.step()) out[s.text(0)].parameters[s.text(1)] = s.text(2);
    return out;
}

// The factors of a stimulus (Observation::factors).
std::vector<std::pair<std::string, std::string>> factors_of(
    const std::string& id, const std::map<std::string, StoredStimulus>& stimuli) {
    std::vector<std::pair<std::string, std::string>> factors;
    const auto it = stimuli.find(id);
    if (it == stimuli.end()) return factors;
    const StoredStimulus& st = it->second;
    if (st.varies.empty()) {
        for (const auto& [name, value] : st.parameters) factors.emplace_back(name, value);
        return factors;
    }
    for (const std::string& f : st.varies) {
        if (f == "technique")
            factors.emplace_back(f, st.technique);
        else if (f.rfind("series:", 0) == 0)  // a comparison series: a level per stimulus
            factors.emplace_back(f.substr(7), id);
        else if (const auto p = st.parameters.find(f); p != st.parameters.end())
            factors.emplace_back(f, p->second);
    }
    return factors;
}

}  // namespace

StudyObservations read_observations(const std::string& db_path,
                                    const ObservationOptions& options) {
    check_database_file(db_path);
    Database db(db_path, SQLITE_OPEN_READONLY);
    if (db.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = 'responses'") == 0)
        throw StoreError(db_path + ": holds no study yet (run a session first)");
    StudyObservations out;
    out.protocol = stored_protocol(db);
    if (out.protocol)
        for (const Block& b : out.protocol->blocks)
            if (is_scaling_task(b.task)) out.choice_orders[b.id] = b.stimuli;
    if (options.analysis) {
        out.sessions = options.sessions;
        if (out.sessions.empty())
            out.sessions = out.protocol ? out.protocol->analysis.sessions : "completed";
        if (out.sessions != "completed" && out.sessions != "all")
            throw StoreError(
                "analysis sessions: expected \"completed\" or \"all\", got '" +
                out.sessions + "'");
    } else {
        out.sessions = "all";
    }
    out.selection = select_sessions(db, db_path, out.sessions,
                                    options.analysis && options.exclude_failed_catch);
    const std::map<std::string, StoredStimulus> stimuli = stored_stimuli(db);

    const int version = static_cast<int>(db.scalar_int("PRAGMA user_version"));
    const std::string kind = trial_kind_sql(version, "t");
    const bool choices = version >= 6, matching = version >= 7;
    Statement s = db.prepare(
        "SELECT p.code, se.uuid, t.position, t.block, " + kind +
        ", r.question, t.practice, t.catch, t.expected_rating, " +
        (choices ? "t.shown" : "NULL") + ", st.stimulus_key, r.rating, r.rt_ms, se.id, " +
        (matching ? "t.start_value, t.final_value, CASE WHEN " + kind +
                        " = 'adjust' THEN (SELECT count(*) FROM adjustments a WHERE "
                        "a.trial_id = t.id) END, coalesce(t.staircase, ''), t.intensity"
                  : "NULL, NULL, NULL, '', NULL") +
        " FROM responses r JOIN trials t ON t.id = r.trial_id "
        "JOIN sessions se ON se.id = r.session_id "
        "JOIN participants p ON p.id = se.participant_id "
        "LEFT JOIN stimuli st ON st.id = t.stimulus_id "
        "ORDER BY p.code, se.id, t.position, r.id");
    while (s.step()) {
        common::Observation row;
        row.participant = s.text(0);
        row.practice = s.integer(6) != 0;
        if (!out.selection.taken.count(s.integer(13))) continue;  // withdrawn, or status
        row.session = s.text(1);
        row.trial = static_cast<int>(s.integer(2));
        row.kind = s.text(4);
        // A kind written by a build that had it is never read as another, even where
        // the analysis would leave the row out.
        const std::optional<Task> task = parse_task(row.kind);
        if (!task)
            throw StoreError(db_path + ": trial " + std::to_string(row.trial) +
                             " of session " + row.session + " has kind '" + row.kind +
                             "', which this build does not know (" + task_names_text() +
                             ")");
        if (options.analysis && (row.practice || !out.selection.keeps(s.integer(13))))
            continue;
        row.analysed_as = (*task)->analysed_as();
        row.block = s.text(3);
        row.question = s.text(5);
        row.is_catch = s.integer(7) != 0;
        if (!s.is_null(8)) row.expected = static_cast<int>(s.integer(8));
        if (!s.is_null(11)) row.response = s.real(11);
        row.rt_ms = s.real(12);
        if ((*task)->is_scaling()) {
            row.shown = shown_from_text(s.text(9));
            const Block* b = out.protocol ? out.protocol->find_block(row.block) : nullptr;
            for (std::size_t k = 0; b && !b->series.empty() && k < row.shown.size();
                 ++k) {
                const auto st = stimuli.find(row.shown[k]);
                if (st == stimuli.end()) continue;
                const auto p = st->second.parameters.find(b->series);
                if (p == st->second.parameters.end()) continue;
                const std::optional<double> value =
                    common::parse_finite_number(p->second);
                if (!value)
                    throw StoreError(db_path + ": block " + row.block +
                                     ": series parameter '" + b->series +
                                     "' of stimulus " + row.shown[k] + " is '" +
                                     p->second + "', not a finite number");
                row.measures["value_" + std::to_string(k + 1)] = *value;
            }
        } else {
            if (!s.is_null(10)) row.shown = {s.text(10)};
            if (!row.shown.empty()) row.factors = factors_of(row.shown.front(), stimuli);
        }
        StoredTrialMeasures stored;
        if (!s.is_null(14)) stored.start_value = s.real(14);
        if (!s.is_null(15)) stored.final_value = s.real(15);
        stored.adjustments = s.is_null(16) ? 0 : s.integer(16);
        stored.staircase = s.text(17);
        if (!s.is_null(18)) stored.intensity = s.real(18);
        (*task)->observe(stored, row);
        out.table.rows.push_back(std::move(row));
    }
    return out;
}

}  // namespace lucent::study
