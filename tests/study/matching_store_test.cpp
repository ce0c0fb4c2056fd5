// Adjustment and staircase trials (issue 31, schema 7) in every store: an SQLite file and
// a real PostgreSQL server (server_environment.h), the station journal of an offline
// station, the exports `matches`, `adjustments` and `staircase`, and merges file to file
// and file to server.
//
// Expected values come from the plan and from what each test recorded itself
// (study_fixtures.h: final_value_for, adjustments_for, intensity_for), never from the
// store under test.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <pqxx/pqxx>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/number_text.h"
#include "study/export.h"
#include "study/postgres/merge_into_server.h"
#include "study/postgres/postgres_store.h"
#include "study/postgres/trial_journal.h"
#include "study/schema.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;
using common::shortest_text;

LocalPostgres& server() { return lucent::test::postgres_server(); }

std::string refusal(const std::function<void()>& call) {
    try {
        call();
    } catch (const StoreError& e) {
        return e.what();
    }
    return "(accepted)";
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
}

// The CSV `write` writes of `db` (a file, or a snapshot of a server), line by line.
std::vector<std::string> export_of(const std::string& db,
                                   int (*write)(const std::string&, std::ostream&)) {
    const ReadableStudyFile file(db);
    std::ostringstream out;
    write(file.path(), out);
    return lines_of(out.str());
}

// The trials of `kind` in plan order; a staircase's slots of one procedure with
// `staircase`.
std::vector<TrialRow> of_kind(const std::vector<TrialRow>& trials, Task kind,
                              const std::string& staircase = "") {
    std::vector<TrialRow> out;
    for (const TrialRow& t : trials)
        if (t.task == kind && (staircase.empty() || t.staircase == staircase))
            out.push_back(t);
    return out;
}

TrialOutcome finishing(const Protocol& p, const TrialRow& t) {
    TrialOutcome o = lucent::test::outcome_for(p, t);
    o.finishes_staircase = true;
    return o;
}

// Every adjustment of `db` (a file, or a server's snapshot) as text with every digit:
// "position step value t_ns input".
std::vector<std::string> adjustment_rows(const std::string& db) {
    const ReadableStudyFile file(db);
    Database d(file.path(), SQLITE_OPEN_READONLY);
    Statement s = d.prepare(
        "SELECT t.position, a.step, a.value, a.t_ns, a.input FROM adjustments a JOIN "
        "trials t ON t.id = a.trial_id ORDER BY t.position, a.step");
    std::vector<std::string> out;
    while (s.step())
        out.push_back(std::to_string(s.integer(0)) + " " + std::to_string(s.integer(1)) +
                      " " + common::full_precision_text(s.real(2)) + " " +
                      std::to_string(s.integer(3)) + " " + s.text(4));
    return out;
}

// What `outcome_for` records for the adjust trials of `trials`, as adjustment_rows
// writes it.
std::vector<std::string> expected_adjustment_rows(const std::vector<TrialRow>& trials) {
    std::vector<std::string> out;
    for (const TrialRow& t : of_kind(trials, Task::adjust)) {
        const int64_t onset = 1000000LL * (t.position + 1);
        int step = 0;
        for (const Adjustment& a : lucent::test::adjustments_for(t.position, onset))
            out.push_back(std::to_string(t.position) + " " + std::to_string(++step) +
                          " " + common::full_precision_text(a.value) + " " +
                          std::to_string(a.t_ns) + " " + a.input);
    }
    return out;
}

// ---- both backends
// ---------------------------------------------------------------------

class Matching : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::string slug;
        for (char c : test)
            slug +=
                std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
        dir_ = lucent::test::scratch_dir("matching_" + slug);
        if (GetParam() == "sqlite") {
            db_ = (dir_ / "study.db").string();
        } else {
            db_ = lucent::test::new_postgres_database("matching_" + slug);
            init_study_store(db_);
        }
    }
    void TearDown() override {
        if (!server().running()) server().start();
    }
    std::unique_ptr<StudyStore> open(const std::string& station = "station") {
        StoreOptions options;
        options.journal_path = (dir_ / (station + "-journal.db")).string();
        options.retry_interval_ms = 0;
        return open_study_store(db_, options);
    }
    // A session of `code` with the protocol's plan; its trials in trials_.
    void start(StudyStore& store, const std::string& code, uint64_t seed) {
        const int64_t study = store.ensure_study(p_);
        int number = 0;
        const int64_t pid = store.ensure_participant(study, code, &number);
        plan_ = plan_trials(p_, seed, number);
        session_ = store.create_session(study, pid, plan_, seed, {});
        trials_ = store.trials(session_.id);
    }
    std::string where(const StudyStore& store, const TrialRow& t) const {
        return store.name() + ": trial " + std::to_string(t.id);
    }

    Protocol p_ = lucent::test::matching_protocol();
    fs::path dir_;
    std::string db_;
    TrialPlan plan_;
    SessionRow session_;
    std::vector<TrialRow> trials_;
};

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    return info.param;
}

TEST_P(Matching, APlanOfAdjustAndStaircaseTrialsRoundTripsWithItsAnswers) {
    auto store = open();
    start(*store, "P1", 5);
    ASSERT_EQ(trials_.size(), plan_.trials.size());
    int64_t adjust = 0, staircase = 0;
    for (size_t i = 0; i < trials_.size(); ++i) {
        SCOPED_TRACE(i);
        const TrialRow& t = trials_[i];
        const PlannedTrial& planned = plan_.trials[i];
        EXPECT_EQ(t.task, planned.task);
        EXPECT_EQ(t.start_value, planned.start_value);
        EXPECT_EQ(t.staircase, planned.staircase);
        EXPECT_EQ(t.expected, planned.expected);
        EXPECT_FALSE(t.final_value || t.intensity || t.choice || t.skipped);
        adjust += t.task == Task::adjust;
        staircase += t.task == Task::staircase;
        if (t.task == Task::adjust) EXPECT_TRUE(t.start_value);
        if (t.task == Task::staircase) EXPECT_FALSE(t.staircase.empty());
    }
    EXPECT_EQ(adjust, 2);     // two targets
    EXPECT_EQ(staircase, 8);  // two procedures of 4 slots
    // kind is authoritative; task keeps the kinds its CHECK knows, NULL for the new ones.
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE kind = 'adjust'"), 2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE kind = 'staircase'"),
              8);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE task IS NULL"),
              adjust + staircase);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE task = kind"),
              static_cast<int64_t>(trials_.size()) - adjust - staircase);

    // An adjust answer with its three changes, a staircase answer with its delta.
    const TrialRow a = of_kind(trials_, Task::adjust).front();
    const TrialRow j = of_kind(trials_, Task::staircase).front();
    const TrialOutcome ao = lucent::test::outcome_for(p_, a);
    ASSERT_EQ(ao.adjustments.size(), 3u);
    EXPECT_FALSE(store->record_trial(session_.id, a.id, ao));
    EXPECT_FALSE(
        store->record_trial(session_.id, j.id, lucent::test::outcome_for(p_, j)));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM adjustments"), 3);
    const auto second = open("reader");
    for (StudyStore* reader : {store.get(), second.get()}) {
        for (const TrialRow& t : reader->trials(session_.id)) {
            SCOPED_TRACE(t.position);
            if (t.id == a.id) {
                EXPECT_TRUE(t.answered);
                EXPECT_EQ(t.final_value, lucent::test::final_value_for(a.position));
                EXPECT_EQ(t.choice, 1);
                EXPECT_FALSE(t.intensity);
            } else if (t.id == j.id) {
                EXPECT_EQ(t.intensity, lucent::test::intensity_for(j.position));
                EXPECT_EQ(t.choice, lucent::test::choice_for(j.position));
                EXPECT_FALSE(t.final_value);
            } else {
                EXPECT_FALSE(t.answered || t.choice || t.final_value || t.intensity);
            }
        }
    }
    store.reset();

    // The exports, from what was recorded: one match, its three adjustments (t_ms from
    // the trial's onset), one staircase row.
    const std::string start = shortest_text(*a.start_value);
    EXPECT_EQ(export_of(db_, export_matches),
              (std::vector<std::string>{
                  "participant,session,trial,block,practice,target,match_knob,"
                  "start_value,final_value,adjustments,total_ms",
                  "P1," + session_.uuid + "," + std::to_string(a.position) + ",m,0," +
                      a.stimulus + ",thickness_exponent," + start + "," +
                      shortest_text(lucent::test::final_value_for(a.position)) + ",3," +
                      shortest_text(700.0 + a.position)}));
    std::vector<std::string> adjustments = {
        "participant,session,trial,block,target,start_value,step,value,t_ms,input"};
    int step = 0;
    for (const Adjustment& x : ao.adjustments)
        adjustments.push_back(
            "P1," + session_.uuid + "," + std::to_string(a.position) + ",m," +
            a.stimulus + "," + start + "," + std::to_string(++step) + "," +
            shortest_text(x.value) + "," +
            shortest_text(static_cast<double>(x.t_ns - ao.onset_ns) / 1e6) + "," +
            x.input);
    EXPECT_EQ(export_of(db_, export_adjustments), adjustments);
    const int choice = lucent::test::choice_for(j.position);
    EXPECT_EQ(export_of(db_, export_staircase),
              (std::vector<std::string>{
                  "participant,session,trial,block,standard,staircase,intensity,"
                  "expected,choice,correct,rt_ms",
                  "P1," + session_.uuid + "," + std::to_string(j.position) + ",j," +
                      j.stimulus + "," + j.staircase + "," +
                      shortest_text(lucent::test::intensity_for(j.position)) + "," +
                      std::to_string(j.expected) + "," + std::to_string(choice) + "," +
                      (choice == j.expected ? "1" : "0") + "," +
                      shortest_text(700.0 + j.position)}));
    // The t_ms of the second change: 600.000123 ms after the onset.
    EXPECT_NE(adjustments[2].find(",600.000123,fine_key"), std::string::npos)
        << adjustments[2];
}

TEST_P(Matching, RefusesAnOutcomeThatDoesNotFitItsTrialsKindStoringNothing) {
    auto store = open();
    start(*store, "P2", 6);
    const TrialRow a = of_kind(trials_, Task::adjust).front();
    const TrialRow j = of_kind(trials_, Task::staircase).front();
    const TrialRow r = of_kind(trials_, Task::rating).front();
    auto record = [&](const TrialRow& t, const TrialOutcome& o) {
        return refusal([&] { store->record_trial(session_.id, t.id, o); });
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    TrialOutcome o = lucent::test::outcome_for(p_, a);
    o.final_value.reset();
    EXPECT_EQ(record(a, o),
              where(*store, a) + " is an adjust trial without a final value");
    o.final_value = nan;
    EXPECT_EQ(record(a, o), where(*store, a) + " has a final value that is not finite");
    o.final_value = inf;
    EXPECT_EQ(record(a, o), where(*store, a) + " has a final value that is not finite");
    o = lucent::test::outcome_for(p_, a);
    o.adjustments[1].value = -inf;
    EXPECT_EQ(record(a, o),
              where(*store, a) + ": adjustment 2 has a value that is not finite");
    o = lucent::test::outcome_for(p_, a);
    o.adjustments[2].input = "mouse";
    EXPECT_EQ(record(a, o), where(*store, a) +
                                ": adjustment 3 has input 'mouse' (expected key, "
                                "fine_key, wheel or drag)");
    o = lucent::test::outcome_for(p_, a);
    o.intensity = 0.5;
    EXPECT_EQ(record(a, o),
              where(*store, a) + " is an adjust trial but carries an intensity");

    o = lucent::test::outcome_for(p_, r);
    o.intensity = 0.25;
    EXPECT_EQ(record(r, o),
              where(*store, r) + " is a rating trial but carries an intensity");
    o = lucent::test::outcome_for(p_, r);
    o.final_value = 1.0;
    EXPECT_EQ(record(r, o),
              where(*store, r) + " is a rating trial but carries a final value");
    o = lucent::test::outcome_for(p_, r);
    o.finishes_staircase = true;
    EXPECT_EQ(record(r, o),
              where(*store, r) + " is a rating trial but finishes a staircase");

    o = lucent::test::outcome_for(p_, j);
    o.intensity.reset();
    EXPECT_EQ(record(j, o),
              where(*store, j) + " is a staircase trial without an intensity");
    o.intensity = nan;
    EXPECT_EQ(record(j, o), where(*store, j) + " has an intensity that is not finite");
    o = lucent::test::outcome_for(p_, j);
    o.adjustments = lucent::test::adjustments_for(j.position, o.onset_ns);
    EXPECT_EQ(record(j, o),
              where(*store, j) + " is a staircase trial but carries adjustments");
    o = lucent::test::outcome_for(p_, j);
    o.responses[0].rating = 3;  // a pair staircase has two places
    EXPECT_EQ(record(j, o), where(*store, j) + ": rating 3 for question '" +
                                p_.find_block("j")->question_id +
                                "' is outside its scale 1..2");

    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"), 0);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM adjustments"), 0);
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM trials WHERE final_value IS NOT NULL "
                         "OR intensity IS NOT NULL OR skipped <> 0"),
        0);
    EXPECT_EQ(store->pending_trials(), 0);
    // Nothing refused is held as answered either: each trial still takes its answer.
    for (const TrialRow& t : {a, j, r})
        EXPECT_FALSE(
            store->record_trial(session_.id, t.id, lucent::test::outcome_for(p_, t)));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM adjustments"), 3);
}

TEST_P(Matching, AFinishedStaircaseSkipsItsOpenSlotsOnlyAndTheRestCompletesTheSession) {
    auto store = open();
    start(*store, "P3", 7);
    const std::vector<TrialRow> a = of_kind(trials_, Task::staircase, "target/a");
    const std::vector<TrialRow> b = of_kind(trials_, Task::staircase, "target/b");
    ASSERT_EQ(a.size(), 4u);
    ASSERT_EQ(b.size(), 4u);
    EXPECT_FALSE(
        store->record_trial(session_.id, a[0].id, lucent::test::outcome_for(p_, a[0])));
    EXPECT_FALSE(
        store->record_trial(session_.id, b[0].id, lucent::test::outcome_for(p_, b[0])));
    EXPECT_FALSE(store->record_trial(session_.id, a[1].id, finishing(p_, a[1])));
    // Exactly a[2] and a[3]: not b's slots, not the answered ones.
    const std::set<int64_t> skipped = {a[2].id, a[3].id};
    const auto second = open("reader");
    for (StudyStore* reader : {store.get(), second.get()})
        for (const TrialRow& t : reader->trials(session_.id)) {
            EXPECT_EQ(t.skipped, skipped.count(t.id) > 0) << t.position;
            EXPECT_EQ(t.answered, t.id == a[0].id || t.id == a[1].id || t.id == b[0].id)
                << t.position;
        }
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE skipped = 1"), 2);
    EXPECT_EQ(refusal([&] {
                  store->record_trial(session_.id, a[2].id,
                                      lucent::test::outcome_for(p_, a[2]));
              }),
              where(*store, a[2]) +
                  " was skipped (its staircase had finished); refusing to record it");
    // The rest answered, the last answer completes the session.
    std::vector<TrialRow> open_trials;
    for (const TrialRow& t : store->trials(session_.id))
        if (!t.answered && !t.skipped) open_trials.push_back(t);
    ASSERT_EQ(open_trials.size(), trials_.size() - 5);
    for (size_t i = 0; i < open_trials.size(); ++i)
        EXPECT_EQ(store->record_trial(session_.id, open_trials[i].id,
                                      lucent::test::outcome_for(p_, open_trials[i])),
                  i + 1 == open_trials.size());
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              static_cast<int64_t>(trials_.size()) - 2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE skipped = 1"), 2);
    EXPECT_TRUE(store->complete_session_if_answered(session_.id));
}

TEST_P(Matching, TheAnswerThatFinishesTheLastStaircaseCompletesTheSessionInOneGo) {
    auto store = open();
    start(*store, "P4", 8);
    const std::vector<TrialRow> a = of_kind(trials_, Task::staircase, "target/a");
    for (const TrialRow& t : trials_)
        if (t.staircase != "target/a")
            EXPECT_FALSE(
                store->record_trial(session_.id, t.id, lucent::test::outcome_for(p_, t)));
    EXPECT_FALSE(
        store->record_trial(session_.id, a[0].id, lucent::test::outcome_for(p_, a[0])));
    EXPECT_TRUE(store->record_trial(session_.id, a[1].id, finishing(p_, a[1])));
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE skipped = 1"), 2);
    // A resume finds nothing open.
    EXPECT_FALSE(store->unfinished_session("P4"));
}

TEST_P(Matching, AWithdrawalDeletesTheAdjustmentsWithTheirTrials) {
    auto store = open();
    start(*store, "P5", 9);
    for (const TrialRow& t : of_kind(trials_, Task::adjust))
        store->record_trial(session_.id, t.id, lucent::test::outcome_for(p_, t));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM adjustments"), 6);
    EXPECT_TRUE(store->withdraw_participant("P5"));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials"), 0);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM adjustments"), 0);
}

INSTANTIATE_TEST_SUITE_P(Stores, Matching, ::testing::Values("sqlite", "postgresql"),
                         param_name);

// ---- a station offline: the journal
// -----------------------------------------------------

class MatchingStation : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = lucent::test::scratch_dir("matching_station");
        uri_ = lucent::test::new_postgres_database("matching_station_" + test);
        init_study_store(uri_);
    }
    void TearDown() override {
        if (!server().running()) server().start();
    }
    std::unique_ptr<StudyStore> open(const std::string& station) {
        StoreOptions o;
        o.journal_path = (dir_ / (station + "-journal.db")).string();
        o.retry_interval_ms = 0;
        return open_study_store(uri_, o);
    }
    Protocol p_ = lucent::test::matching_protocol();
    fs::path dir_;
    std::string uri_;
};

TEST_F(MatchingStation, AnOfflineStationsAdjustAndFinishingStaircaseReachTheServerOnce) {
    int64_t session = 0;
    std::vector<TrialRow> trials;
    std::vector<TrialRow> a;
    TrialRow adjust;
    {
        auto station = open("station");
        const int64_t study = station->ensure_study(p_);
        int number = 0;
        const int64_t pid = station->ensure_participant(study, "P1", &number);
        session =
            station->create_session(study, pid, plan_trials(p_, 3, number), 3, {}).id;
        trials = station->trials(session);
        a = of_kind(trials, Task::staircase, "target/a");
        adjust = of_kind(trials, Task::adjust).front();

        server().stop();
        EXPECT_FALSE(station->record_trial(session, adjust.id,
                                           lucent::test::outcome_for(p_, adjust)));
        EXPECT_FALSE(
            station->record_trial(session, a[0].id, lucent::test::outcome_for(p_, a[0])));
        EXPECT_FALSE(station->record_trial(session, a[1].id, finishing(p_, a[1])));
        EXPECT_EQ(station->pending_trials(), 3);
        // Offline, the station knows what it skipped: the rule refuses a skipped slot.
        EXPECT_EQ(refusal([&] {
                      station->record_trial(session, a[2].id,
                                            lucent::test::outcome_for(p_, a[2]));
                  }),
                  station->name() + ": trial " + std::to_string(a[2].id) +
                      " was skipped (its staircase had finished); refusing to record it");
        EXPECT_EQ(station->pending_trials(), 3);
    }
    server().start();
    {
        // A station started again, before the journal is sent: the journaled answers
        // and the slots they skipped, as they were recorded.
        auto again = open("station");
        for (const TrialRow& t : again->trials(session)) {
            SCOPED_TRACE(t.position);
            const bool skipped = t.id == a[2].id || t.id == a[3].id;
            EXPECT_EQ(t.skipped, skipped);
            EXPECT_EQ(t.answered,
                      t.id == adjust.id || t.id == a[0].id || t.id == a[1].id);
            if (t.id == adjust.id) {
                EXPECT_EQ(t.final_value, lucent::test::final_value_for(t.position));
                EXPECT_EQ(t.choice, 1);
            }
            if (t.id == a[1].id)
                EXPECT_EQ(t.intensity, lucent::test::intensity_for(t.position));
        }
        EXPECT_EQ(again->query_int("SELECT count(*) FROM responses"), 0);  // not yet
        EXPECT_EQ(again->sync(), 3);
        EXPECT_EQ(again->pending_trials(), 0);
        EXPECT_EQ(again->sync(), 0);
    }
    auto check = open("check");
    EXPECT_EQ(check->query_int("SELECT count(*) FROM responses"), 3);
    EXPECT_EQ(check->query_int("SELECT count(*) FROM trials WHERE skipped = 1"), 2);
    EXPECT_EQ(
        check->query_int("SELECT count(*) FROM trials WHERE skipped = 1 AND id IN (" +
                         std::to_string(a[2].id) + ", " + std::to_string(a[3].id) + ")"),
        2);
    EXPECT_EQ(check->query_int("SELECT count(*) FROM adjustments"), 3);
    for (const TrialRow& t : check->trials(session)) {
        if (t.id == adjust.id)
            EXPECT_EQ(t.final_value, lucent::test::final_value_for(t.position));
        else
            EXPECT_FALSE(t.final_value);
        if (t.id == a[0].id || t.id == a[1].id)
            EXPECT_EQ(t.intensity, lucent::test::intensity_for(t.position));
        else
            EXPECT_FALSE(t.intensity);
    }
    std::vector<TrialRow> only_adjust = {adjust};
    EXPECT_EQ(adjustment_rows(uri_), expected_adjustment_rows(only_adjust));
}

// Schema 7 on a server an older build left at schema 6: `lucent store init` fills each
// trial's kind from its task (NULL: a rating), as on a file (store_test.cpp).
TEST_F(MatchingStation, AServerOfSchema6MigratesFillingEachTrialsKindFromItsTask) {
    const std::string uri = lucent::test::new_postgres_database("matching_schema_6");
    lucent::test::migrate_server_to(uri, 6);
    {
        pqxx::connection c(uri);
        pqxx::work tx(c);
        tx.exec(R"sql(
INSERT INTO studies (id, name, protocol_text, protocol_hash, created_utc)
    VALUES (1, 's', 'x', 'h', 'now');
INSERT INTO stimuli (id, study_id, stimulus_key, technique, mesh, image, varies)
    VALUES (1, 1, 'a', 'empirical', 'sphere', '', '');
INSERT INTO participants (id, study_id, code, number, created_utc)
    VALUES (1, 1, 'P1', 1, 'now');
INSERT INTO sessions (id, uuid, study_id, participant_id, machine_id, seed, cell,
    block_order, status, started_utc, software_version, build_hash)
    VALUES (1, 'u', 1, 1, 'm', '1', 0, 'b', 'running', 'now', 'v', 'h');
INSERT INTO trials (session_id, position, block, stimulus_id, practice, catch,
    break_before, task) VALUES (1, 0, 'b', 1, 0, 0, 0, 'pair'),
    (1, 1, 'b', 1, 0, 0, 0, NULL), (1, 2, 'b', 1, 0, 0, 0, 'rating'),
    (1, 3, 'b', 1, 0, 0, 0, 'quadruple');
)sql");
        tx.commit();
    }
    EXPECT_EQ(init_study_store(uri), std::make_pair(6, kSchemaVersion));
    pqxx::connection c(uri);
    pqxx::work tx(c);
    std::vector<std::string> kinds;
    for (const pqxx::row& r :
         tx.exec("SELECT kind, skipped FROM trials ORDER BY position")) {
        kinds.push_back(r[0].as<std::string>());
        EXPECT_EQ(r[1].as<int>(), 0);
    }
    EXPECT_EQ(kinds, (std::vector<std::string>{"pair", "rating", "rating", "quadruple"}));
    EXPECT_EQ(tx.exec("SELECT count(*) FROM adjustments")[0][0].as<int>(), 0);
}

// A journal written before version 1 (no final value, intensity, adjustments) gains them
// when opened, keeping its pending trials.
TEST(MatchingJournal, AnOlderJournalFileGainsTheNewColumnsKeepingItsTrials) {
    const fs::path dir = lucent::test::scratch_dir("matching_journal");
    const std::string path = (dir / "journal.db").string();
    {
        Database old(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        old.exec(R"sql(
CREATE TABLE pending_trials (
    trial_uuid TEXT PRIMARY KEY,
    server TEXT NOT NULL,
    session_uuid TEXT NOT NULL,
    recorded_utc TEXT NOT NULL,
    onset_ns INTEGER NOT NULL,
    confirm_ns INTEGER NOT NULL,
    dropped_frames INTEGER,
    seq INTEGER NOT NULL);
CREATE TABLE pending_responses (
    trial_uuid TEXT NOT NULL REFERENCES pending_trials(trial_uuid) ON DELETE CASCADE,
    question TEXT NOT NULL,
    rating INTEGER NOT NULL,
    rt_ms REAL NOT NULL,
    changes INTEGER NOT NULL,
    first_choice_ns INTEGER NOT NULL,
    final_choice_ns INTEGER NOT NULL,
    PRIMARY KEY (trial_uuid, question));
PRAGMA application_id = 1280656202;
INSERT INTO pending_trials VALUES ('t-old', 'srv', 's-1', '2026-01-01T00:00:00Z', 10, 20,
    NULL, 1);
INSERT INTO pending_responses VALUES ('t-old', 'translucent', 5, 700.5, 1, 11, 12);
)sql");
    }
    TrialJournal journal(path, "srv");
    std::vector<JournaledTrial> pending = journal.pending();
    ASSERT_EQ(pending.size(), 1u);
    EXPECT_EQ(pending[0].trial_uuid, "t-old");
    EXPECT_FALSE(pending[0].outcome.final_value || pending[0].outcome.intensity ||
                 pending[0].outcome.finishes_staircase);
    ASSERT_EQ(pending[0].outcome.responses.size(), 1u);
    EXPECT_EQ(pending[0].outcome.responses[0].rating, 5);

    JournaledTrial adjust{"t-adjust", "s-1", "2026-01-01T00:00:01Z", {}};
    adjust.outcome.onset_ns = 1000;
    adjust.outcome.final_value = 0.1 + 0.2;  // every digit travels
    adjust.outcome.adjustments = lucent::test::adjustments_for(4, 1000);
    adjust.outcome.responses.push_back({"m", 1, 1234.5, 3, 1100, 1200});
    journal.add(adjust);
    JournaledTrial stair{"t-stair", "s-1", "2026-01-01T00:00:02Z", {}};
    stair.outcome.intensity = 1.0 / 3;
    stair.outcome.finishes_staircase = true;
    stair.outcome.responses.push_back({"j", 2, 800, 0, 1, 2});
    journal.add(stair);
    // Another opening (a second station) finds the journal upgraded already.
    TrialJournal second(path, "srv");
    EXPECT_EQ(second.count(), 3);
    const std::optional<JournaledTrial> a = second.find("t-adjust");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->outcome.final_value, 0.1 + 0.2);
    ASSERT_EQ(a->outcome.adjustments.size(), 3u);
    for (size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(a->outcome.adjustments[k].value, adjust.outcome.adjustments[k].value);
        EXPECT_EQ(a->outcome.adjustments[k].t_ns, adjust.outcome.adjustments[k].t_ns);
        EXPECT_EQ(a->outcome.adjustments[k].input, adjust.outcome.adjustments[k].input);
    }
    const std::optional<JournaledTrial> s = second.find("t-stair");
    ASSERT_TRUE(s);
    EXPECT_EQ(s->outcome.intensity, 1.0 / 3);
    EXPECT_TRUE(s->outcome.finishes_staircase);
    EXPECT_FALSE(second.find("t-none"));
    second.remove("t-adjust");
    EXPECT_EQ(Database(path, SQLITE_OPEN_READONLY)
                  .scalar_int("SELECT count(*) FROM pending_adjustments"),
              0);  // removed with its trial
}

// ---- merges
// ------------------------------------------------------------------------------

class MatchingMerge : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = lucent::test::scratch_dir("matching_merge");
        uri_ = lucent::test::new_postgres_database("matching_merge_" + test);
        init_study_store(uri_);
    }
    void TearDown() override {
        if (!server().running()) server().start();
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // A station file's session: copied to paused.db once the adjust trials and a
    // staircase's first slot are answered, then every trial, the "target/a" procedure
    // finishing at its second slot (its last two skipped), copied to completed.db.
    void paused_and_completed_copies() {
        const std::string station = path("station.db");
        std::vector<TrialRow> trials;
        {
            Store store(station);
            const int64_t study = store.ensure_study(p_);
            int number = 0;
            const int64_t pid = store.ensure_participant(study, "P07", &number);
            const SessionRow s =
                store.create_session(study, pid, plan_trials(p_, 11, number), 11, {});
            session_ = s.id;
            uuid_ = s.uuid;
            trials = store.trials(s.id);
            a_ = of_kind(trials, Task::staircase, "target/a");
            for (const TrialRow& t : of_kind(trials, Task::adjust))
                store.record_trial(s.id, t.id, lucent::test::outcome_for(p_, t));
            store.record_trial(s.id, a_[0].id, lucent::test::outcome_for(p_, a_[0]));
            store.set_status(s.id, "paused", true);
        }
        fs::copy_file(station, path("paused.db"));
        {
            Store store(station);
            store.begin_segment(session_, {});
            store.set_status(session_, "running", false);
            store.record_trial(session_, a_[1].id, finishing(p_, a_[1]));
            for (const TrialRow& t : store.trials(session_))
                if (!t.answered && !t.skipped)
                    store.record_trial(session_, t.id, lucent::test::outcome_for(p_, t));
        }
        fs::copy_file(station, path("completed.db"));
        trials_ = trials;
    }
    int64_t count(const std::string& db, const std::string& sql) {
        const ReadableStudyFile file(db);
        return Database(file.path(), SQLITE_OPEN_READONLY).scalar_int(sql);
    }
    // The three exports of `db`, for comparing two databases.
    std::vector<std::string> exports(const std::string& db) {
        std::vector<std::string> out;
        for (auto write : {export_matches, export_adjustments, export_staircase})
            for (const std::string& line : export_of(db, write)) out.push_back(line);
        return out;
    }
    // A copy of completed.db with `sql` applied.
    std::string edited(const std::string& name, const std::string& sql) {
        fs::copy_file(path("completed.db"), path(name));
        Database(path(name), SQLITE_OPEN_READWRITE).exec(sql);
        return path(name);
    }

    Protocol p_ = lucent::test::matching_protocol();
    fs::path dir_;
    std::string uri_, uuid_;
    int64_t session_ = 0;
    std::vector<TrialRow> trials_, a_;
};

TEST_F(MatchingMerge, FileToFileCarriesAdjustmentsAndSkippedSlotsOnce) {
    paused_and_completed_copies();
    const std::vector<std::string> expected = exports(path("completed.db"));
    // Headers and 2 matches, 6 adjustments, 6 staircase answers (2 of a, 4 of b).
    ASSERT_EQ(expected.size(), (1u + 2u) + (1u + 6u) + (1u + 6u));
    EXPECT_EQ(adjustment_rows(path("completed.db")), expected_adjustment_rows(trials_));
    // The same file twice, and the paused copy with it in either order: once each.
    for (const auto& inputs :
         {std::vector<std::string>{path("completed.db"), path("completed.db")},
          std::vector<std::string>{path("paused.db"), path("completed.db")},
          std::vector<std::string>{path("completed.db"), path("paused.db")}}) {
        const std::string out = path("out.db");
        fs::remove(out);
        const MergeReport report = merge_databases(inputs, out);
        EXPECT_EQ(report.sessions_added, 1);
        EXPECT_EQ(exports(out), expected);
        EXPECT_EQ(adjustment_rows(out), expected_adjustment_rows(trials_));
        EXPECT_EQ(count(out, "SELECT count(*) FROM trials WHERE skipped = 1"), 2);
        EXPECT_EQ(count(out,
                        "SELECT count(*) FROM trials WHERE skipped = 1 AND position "
                        "IN (" +
                            std::to_string(a_[2].position) + ", " +
                            std::to_string(a_[3].position) + ")"),
                  2);
        EXPECT_EQ(count(out, "SELECT count(*) FROM sessions WHERE status = 'completed'"),
                  1);
        // A merge of the merge adds nothing either.
        const std::string again = path("again.db");
        fs::remove(again);
        merge_databases({out, path("completed.db")}, again);
        EXPECT_EQ(exports(again), expected);
    }
}

TEST_F(MatchingMerge, ACopyDisagreeingOnAMatchOrAStaircaseIsRefusedNamingTheTrial) {
    paused_and_completed_copies();
    const TrialRow adjust = of_kind(trials_, Task::adjust).front();
    const std::string trial = std::to_string(adjust.position);
    struct Case {
        std::string file, sql, says, also = "";
    };
    const double final_value = lucent::test::final_value_for(adjust.position);
    const std::vector<Case> cases = {
        {"final.db",
         "UPDATE trials SET final_value = final_value + 0.5 WHERE position = " + trial,
         "trial " + trial + ": final_value ", shortest_text(final_value) + " in "},
        {"step.db",
         "UPDATE adjustments SET value = value + 1 WHERE step = 2 AND trial_id = "
         "(SELECT id FROM trials WHERE position = " +
             trial + ")",
         "trial " + trial + ": adjustment 2 "},
        {"fewer.db",
         "DELETE FROM adjustments WHERE step = 3 AND trial_id = (SELECT id FROM trials "
         "WHERE position = " +
             trial + ")",
         "trial " + trial + ": adjustment 3 "},
        {"intensity.db",
         "UPDATE trials SET intensity = intensity * 2 WHERE position = " +
             std::to_string(a_[0].position),
         "trial " + std::to_string(a_[0].position) + ": intensity "},
        {"unskipped.db",
         "UPDATE trials SET skipped = 0 WHERE position = " +
             std::to_string(a_[2].position) +
             "; INSERT INTO responses (session_id, trial_id, question, rating, rt_ms, "
             "changes, first_choice_ns, final_choice_ns) SELECT session_id, id, '" +
             p_.find_block("j")->question_id +
             "', 1, 1, 0, 1, 1 FROM trials WHERE position = " +
             std::to_string(a_[2].position),
         "trial " + std::to_string(a_[2].position) + ": "},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        const std::string file = edited(c.file, c.sql);
        for (const auto& inputs :
             {std::vector<std::string>{path("completed.db"), file},
              std::vector<std::string>{file, path("completed.db")}}) {
            const std::string out = path("out.db");
            const std::string what = refusal([&] { merge_databases(inputs, out); });
            EXPECT_NE(what.find("refusing to merge: session " + uuid_ + " (P07)"),
                      std::string::npos)
                << what;
            EXPECT_NE(what.find(c.says), std::string::npos) << what;
            EXPECT_NE(what.find(c.also), std::string::npos) << what;
            EXPECT_NE(what.find(c.file), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_FALSE(fs::exists(out));
        }
    }
}

TEST_F(MatchingMerge, FileToServerCarriesAdjustmentsOnceExtendingAPausedCopy) {
    paused_and_completed_copies();
    const std::vector<std::string> expected = exports(path("completed.db"));
    // The paused copy first: a new session on the server with its adjustments.
    EXPECT_EQ(merge_into_server({path("paused.db")}, uri_).sessions_added, 1);
    EXPECT_EQ(exports(uri_), exports(path("paused.db")));
    EXPECT_EQ(count(uri_, "SELECT count(*) FROM adjustments"), 6);
    // Then the completed copy extends it: the finishing answer, the skipped slots.
    const MergeReport extended = merge_into_server({path("completed.db")}, uri_);
    EXPECT_EQ(extended.sessions_added, 0);
    EXPECT_EQ(extended.sessions_extended, 1);
    EXPECT_EQ(exports(uri_), expected);
    EXPECT_EQ(adjustment_rows(uri_), expected_adjustment_rows(trials_));
    EXPECT_EQ(count(uri_, "SELECT count(*) FROM trials WHERE skipped = 1"), 2);
    EXPECT_EQ(count(uri_, "SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
    // Again, and both files at once: nothing doubles.
    merge_into_server({path("completed.db")}, uri_);
    merge_into_server({path("paused.db"), path("completed.db")}, uri_);
    EXPECT_EQ(exports(uri_), expected);
    EXPECT_EQ(count(uri_, "SELECT count(*) FROM adjustments"), 6);
    // A copy with another final value is refused, and the server keeps its own.
    const TrialRow adjust = of_kind(trials_, Task::adjust).front();
    const std::string file =
        edited("final.db",
               "UPDATE trials SET final_value = 0.5 + final_value WHERE "
               "position = " +
                   std::to_string(adjust.position));
    const std::string what = refusal([&] { merge_into_server({file}, uri_); });
    EXPECT_NE(what.find("trial " + std::to_string(adjust.position) + ": final_value"),
              std::string::npos)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(exports(uri_), expected);
}

TEST_F(MatchingMerge, ANewSessionReachesTheServerWithEveryDigitOfItsValues) {
    const std::string station = path("station.db");
    {
        Store store(station);
        const int64_t study = store.ensure_study(p_);
        const int64_t pid = store.ensure_participant(study, "P9", nullptr);
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p_, 2, 9), 2, {});
        for (const TrialRow& t : store.trials(s.id)) {
            TrialOutcome o = lucent::test::outcome_for(p_, t);
            if (o.final_value) *o.final_value += 0.1 + 0.2;  // 17 significant digits
            if (o.intensity) *o.intensity = 1.0 / 3;
            store.record_trial(s.id, t.id, o);
        }
    }
    EXPECT_EQ(merge_into_server({station}, uri_).sessions_added, 1);
    EXPECT_EQ(exports(uri_), exports(station));
    EXPECT_EQ(count(uri_, "SELECT count(*) FROM trials WHERE intensity = 1.0 / 3"), 8);
    EXPECT_EQ(adjustment_rows(uri_), adjustment_rows(station));
}

}  // namespace
}  // namespace lucent::study
