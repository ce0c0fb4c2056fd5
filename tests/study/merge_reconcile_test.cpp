// Copies of one session in a merge (issue 26 item 1), and one code on one machine in two
// files (item 6). Expected values are the ratings each test wrote itself.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "study/export.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;

// Ratings by (trial position, question), as a test wrote them or a database holds them.
using Ratings = std::map<std::pair<int64_t, std::string>, int64_t>;

Ratings ratings_of_session(const std::string& db_path, const std::string& uuid) {
    Database db(db_path, SQLITE_OPEN_READONLY);
    Statement s = db.prepare(
        "SELECT t.position, r.question, r.rating FROM responses r JOIN trials t ON "
        "t.id = r.trial_id JOIN sessions se ON se.id = r.session_id WHERE se.uuid = ?");
    s.bind(1, uuid);
    Ratings out;
    while (s.step()) out[{s.integer(0), s.text(1)}] = s.integer(2);
    return out;
}

std::string text_of(const std::string& db_path, const std::string& sql) {
    Database db(db_path, SQLITE_OPEN_READONLY);
    Statement s = db.prepare(sql);
    return s.step() ? s.text(0) : "(no row)";
}

int64_t count_of(const std::string& db_path, const std::string& sql) {
    return Database(db_path, SQLITE_OPEN_READONLY).scalar_int(sql);
}

class MergeReconcile : public ::testing::Test {
protected:
    void SetUp() override { dir_ = lucent::test::scratch_dir("merge_reconcile"); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // Starts a session of `code` in `db`; returns its id.
    int64_t start(const std::string& db, const std::string& code, uint64_t seed,
                  const std::string& machine = "") {
        Store store(db);
        const int64_t study = store.ensure_study(p_);
        int number = 0;
        const int64_t pid = store.ensure_participant(study, code, &number);
        SessionEnvironment env;
        env.machine_id = machine;
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p_, seed, number), seed, env);
        uuid_[s.id] = s.uuid;
        return s.id;
    }
    // Answers the next `n` unanswered trials (all when n < 0), recording what it wrote.
    void answer(const std::string& db, int64_t session, int n) {
        Store store(db);
        for (const TrialRow& t : store.trials(session)) {
            if (t.answered) continue;
            if (n-- == 0) break;
            const TrialOutcome o = lucent::test::outcome_for(p_, t);
            for (const Response& r : o.responses)
                written_[{t.position, r.question}] = r.rating;
            store.record_trial(session, t.id, o);
        }
    }
    void set_status(const std::string& db, int64_t session, const std::string& status) {
        Store(db).set_status(session, status, status != "running");
    }
    // A session copied mid-way (paused after 2 trials = 4 ratings) and at the end.
    void paused_and_completed_copies() {
        const std::string station = path("station.db");
        session_ = start(station, "P07", 7);
        answer(station, session_, 2);
        set_status(station, session_, "paused");
        fs::copy_file(station, path("paused.db"));  // the store is closed: no -wal left
        {
            Store store(station);
            store.begin_segment(session_, {});  // the resume
        }
        set_status(station, session_, "running");
        answer(station, session_, -1);
        fs::copy_file(station, path("completed.db"));
    }

    Protocol p_ = lucent::test::small_protocol();
    fs::path dir_;
    std::map<int64_t, std::string> uuid_;
    Ratings written_;
    int64_t session_ = 0;
};

TEST_F(MergeReconcile, PausedCopyThenCompletedCopyKeepsAllTenRatings) {
    paused_and_completed_copies();
    ASSERT_EQ(written_.size(), 10u);  // 5 trials x 2 questions
    const std::string uuid = uuid_.at(session_);
    ASSERT_EQ(ratings_of_session(path("paused.db"), uuid).size(), 4u);
    // Either order: the completed copy extends the paused one and wins.
    for (const auto& [order, inputs] : std::map<std::string, std::vector<std::string>>{
             {"paused_first", {path("paused.db"), path("completed.db")}},
             {"completed_first", {path("completed.db"), path("paused.db")}}}) {
        SCOPED_TRACE(order);
        const std::string out = path(order + ".db");
        const MergeReport report = merge_databases(inputs, out);
        EXPECT_EQ(report.sessions_added, 1);
        EXPECT_EQ(report.sessions_extended, 1);
        EXPECT_EQ(report.sessions_already_present, 0);
        EXPECT_EQ(ratings_of_session(out, uuid), written_);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM responses"), 10);
        EXPECT_EQ(text_of(out, "SELECT status FROM sessions"), "completed");
        EXPECT_NE(text_of(out, "SELECT ended_utc FROM sessions"), "");
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM session_segments"),
                  2);  // start, resume
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM trials WHERE answered_utc IS NULL"),
                  0);
        EXPECT_EQ(text_of(out, "SELECT group_concat(code) FROM participants"), "P07");
    }
}

TEST_F(MergeReconcile, IdenticalCopiesAreAlreadyPresentNotExtended) {
    paused_and_completed_copies();
    fs::copy_file(path("completed.db"), path("completed2.db"));
    const MergeReport report = merge_databases(
        {path("completed.db"), path("paused.db"), path("completed2.db")}, path("out.db"));
    EXPECT_EQ(report.sessions_added, 1);
    EXPECT_EQ(report.sessions_extended, 1);         // the paused copy
    EXPECT_EQ(report.sessions_already_present, 1);  // the second completed copy
    EXPECT_EQ(count_of(path("out.db"), "SELECT count(*) FROM responses"), 10);
}

TEST_F(MergeReconcile, DisagreeingRatingIsRefusedNamingSessionAndTrial) {
    paused_and_completed_copies();
    const std::string uuid = uuid_.at(session_);
    // Trial 3 (answered after the pause) rated otherwise in a second copy of the end.
    fs::copy_file(path("completed.db"), path("edited.db"));
    int64_t position = -1, written = 0;
    for (const auto& [key, rating] : written_)
        if (key.second == "translucent" && key.first > 1) {
            position = key.first;
            written = rating;
            break;
        }
    ASSERT_GE(position, 0);
    const int64_t other = written % 7 + 1;
    Database(path("edited.db"), SQLITE_OPEN_READWRITE)
        .prepare(
            "UPDATE responses SET rating = ? WHERE question = 'translucent' AND trial_id "
            "= "
            "(SELECT id FROM trials WHERE position = ?)")
        .bind(1, other)
        .bind(2, position)
        .run();
    for (const auto& inputs :
         {std::vector<std::string>{path("completed.db"), path("edited.db")},
          std::vector<std::string>{path("edited.db"), path("completed.db")}}) {
        const std::string out = path("out.db");
        try {
            merge_databases(inputs, out);
            ADD_FAILURE() << "merged two copies that disagree";
        } catch (const StoreError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("refusing to merge"), std::string::npos) << what;
            EXPECT_NE(what.find(uuid), std::string::npos) << what;
            EXPECT_NE(what.find("(P07)"), std::string::npos) << what;
            EXPECT_NE(what.find("trial " + std::to_string(position)), std::string::npos)
                << what;
            EXPECT_NE(what.find("'translucent'"), std::string::npos) << what;
            EXPECT_NE(what.find(std::to_string(written) + " in"), std::string::npos)
                << what;
            EXPECT_NE(what.find(std::to_string(other) + " in"), std::string::npos)
                << what;
            EXPECT_NE(what.find("edited.db"), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos);
        }
        EXPECT_FALSE(fs::exists(out));
    }
    // The paused copy agrees with both on what it holds: still refused, the pair
    // disagrees.
    EXPECT_THROW(
        merge_databases({path("paused.db"), path("edited.db"), path("completed.db")},
                        path("out.db")),
        StoreError);
}

TEST_F(MergeReconcile, CopiesThatEachHoldAnswersTheOtherLacksAreRefused) {
    paused_and_completed_copies();
    fs::copy_file(path("completed.db"), path("a.db"));
    fs::copy_file(path("completed.db"), path("b.db"));
    // a lacks the last trial's answers, b the one before.
    for (const auto& [file, offset] :
         {std::pair{std::string("a.db"), 0}, std::pair{std::string("b.db"), 1}}) {
        Database db(path(file), SQLITE_OPEN_READWRITE);
        db.prepare(
              "DELETE FROM responses WHERE trial_id = (SELECT id FROM trials ORDER BY "
              "position DESC LIMIT 1 OFFSET ?)")
            .bind(1, offset)
            .run();
        db.exec("UPDATE sessions SET status = 'paused'");
    }
    try {
        merge_databases({path("a.db"), path("b.db")}, path("out.db"));
        ADD_FAILURE() << "merged two copies neither of which extends the other";
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find(uuid_.at(session_)), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("neither copy extends the other"),
                  std::string::npos)
            << e.what();
    }
    // The completed copy extends both: with it the three reconcile, in any order.
    const MergeReport report = merge_databases(
        {path("a.db"), path("b.db"), path("completed.db")}, path("out.db"));
    EXPECT_EQ(report.sessions_extended, 1);
    EXPECT_EQ(ratings_of_session(path("out.db"), uuid_.at(session_)), written_);
}

TEST_F(MergeReconcile, OneSessionUuidUnderTwoCodesIsRefused) {
    paused_and_completed_copies();
    Database(path("paused.db"), SQLITE_OPEN_READWRITE)
        .exec("UPDATE participants SET code = 'P08'");
    try {
        merge_databases({path("paused.db"), path("completed.db")}, path("out.db"));
        ADD_FAILURE() << "merged one session under two codes";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(uuid_.at(session_)), std::string::npos) << what;
        EXPECT_NE(what.find("P08"), std::string::npos) << what;
        EXPECT_NE(what.find("P07"), std::string::npos) << what;
    }
}

// ---- item 6: one code, one machine, two files ---------------------------------------

class Merge : public MergeReconcile {};

TEST_F(Merge, TwoCompletedSessionsOfOneCodeFromOneMachineAreTwoPeople) {
    // Two study files on one lab machine, each with a completed P01: two people (a file
    // refuses a second run of a code that completed).
    const std::string machine = "labmachine-0001";
    const std::string a = path("monday.db"), b = path("tuesday.db");
    const int64_t first = start(a, "P01", 1, machine);
    const std::string first_uuid = uuid_.at(first);  // both files number their session 1
    answer(a, first, -1);
    const Ratings first_ratings = written_;
    written_.clear();
    const int64_t second = start(b, "P01", 2, machine);
    const std::string second_uuid = uuid_.at(second);
    answer(b, second, -1);
    const Ratings second_ratings = written_;
    // Tell the two apart by start time: Monday's session came first.
    Database(a, SQLITE_OPEN_READWRITE)
        .exec("UPDATE sessions SET started_utc = '2024-03-04T09:00:00.000Z'");
    Database(b, SQLITE_OPEN_READWRITE)
        .exec("UPDATE sessions SET started_utc = '2024-03-05T09:00:00.000Z'");
    for (const auto& inputs :
         {std::vector<std::string>{a, b}, std::vector<std::string>{b, a}}) {
        const std::string out = path("out_" + std::to_string(inputs[0] == a) + ".db");
        const MergeReport report = merge_databases(inputs, out);
        EXPECT_EQ(report.sessions_added, 2);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM participants"), 2);
        EXPECT_EQ(text_of(out,
                          "SELECT p.code FROM participants p JOIN sessions s ON "
                          "s.participant_id = p.id WHERE s.uuid = '" +
                              first_uuid + "'"),
                  "P01@labmachi#1");
        EXPECT_EQ(text_of(out,
                          "SELECT p.code FROM participants p JOIN sessions s ON "
                          "s.participant_id = p.id WHERE s.uuid = '" +
                              second_uuid + "'"),
                  "P01@labmachi#2");
        EXPECT_EQ(ratings_of_session(out, first_uuid), first_ratings);
        EXPECT_EQ(ratings_of_session(out, second_uuid), second_ratings);
        ASSERT_EQ(report.notes.size(), 1u);
        EXPECT_NE(report.notes[0].find("2 people on machine labmachi"), std::string::npos)
            << report.notes[0];
        EXPECT_NE(report.notes[0].find("P01@labmachi#1 P01@labmachi#2"),
                  std::string::npos)
            << report.notes[0];
    }
}

TEST_F(Merge, OneSessionInTwoFilesOfOneMachineIsOnePerson) {
    // The same completed session in both files (a backup and the file) plus a second
    // participant only in the later file: nobody is split.
    const std::string machine = "labmachine-0001";
    const std::string a = path("backup.db");
    const int64_t s = start(a, "P01", 1, machine);
    answer(a, s, -1);
    fs::copy_file(a, path("later.db"));
    start(path("later.db"), "P02", 2, machine);
    const MergeReport report = merge_databases({a, path("later.db")}, path("out.db"));
    EXPECT_TRUE(report.notes.empty());
    EXPECT_EQ(text_of(path("out.db"),
                      "SELECT group_concat(code, ' ') FROM (SELECT code FROM "
                      "participants ORDER BY code)"),
              "P01 P02");
}

}  // namespace
}  // namespace lucent::study
