// Merges into a study server and the station journal against withdrawals and later
// copies (issue 26 items 1 and 2), on the suite's real PostgreSQL server. Expected
// values are the ratings and sessions each test wrote itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <sstream>

#include "study/export.h"
#include "study/postgres/merge_into_server.h"
#include "study/sha256.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;

class OnServer : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = lucent::test::scratch_dir("merge_server_" + test);
        uri_ = lucent::test::new_postgres_database(test);
        init_study_store(uri_);
    }
    void TearDown() override {
        if (!lucent::test::postgres_server().running())
            lucent::test::postgres_server().start();
    }
    StoreOptions options(const std::string& station) {
        StoreOptions o;
        o.journal_path = (dir_ / (station + "-journal.db")).string();
        o.retry_interval_ms = 0;
        return o;
    }
    std::unique_ptr<StudyStore> server(const std::string& station = "check") {
        return open_study_store(uri_, options(station));
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // A session of `code` in a station file, `answered` trials rated (all when < 0).
    int64_t session(Store& store, const std::string& code, uint64_t seed,
                    int answered = -1) {
        const int64_t study = store.ensure_study(p_);
        int number = 0;
        const int64_t pid = store.ensure_participant(study, code, &number);
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p_, seed, number), seed, {});
        uuid_ = s.uuid;
        for (const TrialRow& t : store.trials(s.id)) {
            if (answered-- == 0) break;
            store.record_trial(s.id, t.id, lucent::test::outcome_for(p_, t));
        }
        return s.id;
    }
    Protocol p_ = lucent::test::small_protocol();
    fs::path dir_;
    std::string uri_, uuid_;
};

class Withdrawal : public OnServer {};
class MergeReconcile : public OnServer {};

TEST_F(Withdrawal, MergingAStationFileIntoAServerDoesNotBringAWithdrawnParticipantBack) {
    const std::string station = path("station.db");
    {
        Store store(station);
        session(store, "P01", 1);
        session(store, "P02", 2);
    }
    EXPECT_EQ(merge_into_server({station}, uri_).sessions_added, 2);
    EXPECT_TRUE(server()->withdraw_participant("P01"));
    const MergeReport again = merge_into_server({station}, uri_);
    EXPECT_EQ(again.sessions_withdrawn, 1);
    EXPECT_EQ(again.sessions_added, 0);
    auto s = server();
    EXPECT_EQ(s->query_int("SELECT count(*) FROM sessions"), 1);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM participants WHERE code = 'P01'"), 0);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM responses"), 5 * 2);  // P02's 5 trials
    EXPECT_EQ(s->query_int("SELECT count(*) FROM withdrawn_sessions"), 1);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM withdrawn_codes"), 1);
    // The code row is the hash of salt + code + "\n" + machine, never the code.
    s->snapshot_to_sqlite(path("snapshot.db"));
    Database snap(path("snapshot.db"), SQLITE_OPEN_READONLY);
    Statement c = snap.prepare("SELECT salt, code_hash FROM withdrawn_codes");
    ASSERT_TRUE(c.step());
    EXPECT_EQ(c.text(1), sha256_hex(c.text(0) + "P01\n"));
}

// Issue 44 item 6: a station file's series pictures reach the server once per set,
// however often the file is merged, and the merged segment names its set.
TEST_F(Withdrawal, MergingIntoAServerCarriesSeriesPicturesOncePerSet) {
    const std::string station = path("station.db");
    {
        Store store(station);
        const int64_t study = store.ensure_study(p_);
        SessionEnvironment env;
        env.machine_id = "web";
        for (int i = 1; i <= 3; ++i) {
            StimulusProvenance picture;
            picture.stimulus = "a@k=0." + std::to_string(i);
            picture.source = "images";
            picture.file = picture.stimulus + ".png";
            picture.content_hash = "h" + std::to_string(i);
            picture.software_version = "9.9.9";
            picture.build_hash = "test";
            env.series_pictures.push_back(picture);
        }
        for (const char* code : {"P01", "P02"}) {
            int number = 0;
            const int64_t pid = store.ensure_participant(study, code, &number);
            store.create_session(study, pid, plan_trials(p_, 1, number), 1, env);
        }
    }
    EXPECT_EQ(merge_into_server({station}, uri_).sessions_added, 2);
    merge_into_server({station}, uri_);
    auto s = server();
    EXPECT_EQ(s->query_int("SELECT count(*) FROM series_pictures"), 3);
    EXPECT_EQ(
        s->query_int("SELECT count(*) FROM session_segments g JOIN series_pictures x "
                     "ON x.set_hash = g.series_set AND x.picture = 'a@k=0.2' AND "
                     "x.content_hash = 'h2'"),
        2);
}

TEST_F(Withdrawal, AWithdrawalInAFileRemovesTheSessionFromTheServer) {
    const std::string station = path("station.db"), study = path("study.db");
    {
        Store store(station);
        session(store, "P01", 1);
        session(store, "P02", 2);
    }
    merge_into_server({station}, uri_);
    fs::copy_file(station, study);
    Store(study).withdraw_participant("P01");
    const MergeReport report = merge_into_server({study}, uri_);
    EXPECT_EQ(report.sessions_withdrawn, 1);
    auto s = server();
    EXPECT_EQ(s->query_int("SELECT count(*) FROM sessions"), 1);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM participants WHERE code = 'P01'"), 0);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM responses"), 5 * 2);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM withdrawn_sessions"), 1);
    EXPECT_EQ(
        s->query_int("SELECT count(*) FROM retired_participant_numbers WHERE number = 1"),
        1);
}

TEST_F(Withdrawal, StoreSyncDoesNotResendAWithdrawnSession) {
    auto station = server("station");
    const int64_t study = station->ensure_study(p_);
    int number = 0;
    const int64_t pid = station->ensure_participant(study, "P04", &number);
    const SessionRow s =
        station->create_session(study, pid, plan_trials(p_, 4, number), 4, {});
    const std::vector<TrialRow> trials = station->trials(s.id);
    station->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p_, trials[0]));
    lucent::test::postgres_server().stop();
    for (size_t i = 1; i < 3; ++i)  // journaled: the server is away
        station->record_trial(s.id, trials[i].id,
                              lucent::test::outcome_for(p_, trials[i]));
    EXPECT_EQ(station->pending_trials(), 2);
    lucent::test::postgres_server().start();
    EXPECT_TRUE(server("admin")->withdraw_participant("P04"));
    EXPECT_EQ(station->sync(), 0);  // nothing confirmed, nothing refused
    EXPECT_EQ(station->pending_trials(), 0);
    EXPECT_EQ(station->withdrawn_trials_dropped(), 2);
    auto check = server();
    EXPECT_EQ(check->query_int("SELECT count(*) FROM sessions"), 0);
    EXPECT_EQ(check->query_int("SELECT count(*) FROM responses"), 0);
    EXPECT_EQ(check->query_int("SELECT count(*) FROM withdrawn_sessions"), 1);
}

TEST_F(MergeReconcile, IntoAServerThePausedServerCopyIsExtendedByTheCompletedFile) {
    const std::string station = path("station.db");
    int64_t id = 0;
    {
        Store store(station);
        id = session(store, "P07", 7, 2);  // 2 trials = 4 ratings
        store.set_status(id, "paused", true);
    }
    fs::copy_file(station, path("paused.db"));
    {
        Store store(station);
        store.begin_segment(id, {});
        store.set_status(id, "running", false);
        for (const TrialRow& t : store.trials(id))
            if (!t.answered)
                store.record_trial(id, t.id, lucent::test::outcome_for(p_, t));
    }
    merge_into_server({path("paused.db")}, uri_);
    auto s = server();
    EXPECT_EQ(s->query_int("SELECT count(*) FROM responses"), 4);
    const int64_t server_id = s->query_int("SELECT id FROM sessions");
    const MergeReport report = merge_into_server({station}, uri_);
    EXPECT_EQ(report.sessions_extended, 1);
    EXPECT_EQ(report.sessions_added, 0);
    EXPECT_EQ(s->query_int("SELECT id FROM sessions"), server_id);  // the same row
    EXPECT_EQ(s->query_int("SELECT count(*) FROM responses"), 10);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM sessions WHERE status = 'completed' AND "
                           "ended_utc IS NOT NULL"),
              1);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM session_segments"), 2);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM trials WHERE answered_utc IS NULL"), 0);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM trials t WHERE segment_id IS NULL"), 0);
    // Each rating as the station wrote it (rating_for; catch trials 7).
    s->snapshot_to_sqlite(path("snapshot.db"));
    Database snap(path("snapshot.db"), SQLITE_OPEN_READONLY);
    Statement r = snap.prepare(
        "SELECT t.position, t.catch, r.question, r.rating FROM responses r "
        "JOIN trials t ON t.id = r.trial_id");
    int checked = 0;
    while (r.step()) {
        const int q = r.text(2) == "translucent" ? 0 : 1;
        EXPECT_EQ(r.integer(3),
                  r.integer(1) ? 7 : lucent::test::rating_for(int(r.integer(0)), q));
        ++checked;
    }
    EXPECT_EQ(checked, 10);
    // The paused copy again: the server's copy extends it; nothing changes.
    const MergeReport again = merge_into_server({path("paused.db")}, uri_);
    EXPECT_EQ(again.sessions_extended, 0);
    EXPECT_EQ(again.sessions_already_present, 1);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM responses"), 10);
    EXPECT_EQ(s->query_int("SELECT count(*) FROM session_segments"), 2);
}

TEST_F(MergeReconcile, IntoAServerADisagreeingCopyIsRefusedAndNothingChanges) {
    const std::string station = path("station.db");
    {
        Store store(station);
        session(store, "P07", 7);
    }
    merge_into_server({station}, uri_);
    fs::copy_file(station, path("edited.db"));
    Database(path("edited.db"), SQLITE_OPEN_READWRITE)
        .exec(
            "UPDATE responses SET rating = rating % 7 + 1 WHERE question = 'realistic' "
            "AND "
            "trial_id = (SELECT id FROM trials WHERE position = 2)");
    try {
        merge_into_server({path("edited.db")}, uri_);
        ADD_FAILURE() << "merged a copy that disagrees with the server";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(uuid_), std::string::npos) << what;
        EXPECT_NE(what.find("trial 2"), std::string::npos) << what;
        EXPECT_NE(what.find("'realistic'"), std::string::npos) << what;
        EXPECT_NE(what.find(uri_), std::string::npos) << what;  // the server by its URI
    }
    auto s = server();
    EXPECT_EQ(s->query_int("SELECT count(*) FROM responses"), 10);
}

// Forced choices (issue 30) reach the server through a merge with their task and screen
// order, each once; a second merge adds nothing. Expected: the file's own export.
class MergeChoices : public OnServer {};

TEST_F(MergeChoices, AStationFilesChoicesReachTheServerOnceWithTheirScreenOrder) {
    p_ = lucent::test::choice_protocol();
    {
        Store station(path("station.db"));
        session(station, "P1", 4);
        session(station, "P2", 5);
    }
    EXPECT_EQ(merge_into_server({path("station.db")}, uri_).sessions_added, 2);
    EXPECT_EQ(merge_into_server({path("station.db")}, uri_).sessions_added, 0);
    auto rows = [](const std::string& db) {
        std::ostringstream out;
        export_choices(db, out);
        std::vector<std::string> lines;
        std::istringstream in(out.str());
        for (std::string line; std::getline(in, line);) lines.push_back(line);
        std::sort(lines.begin(), lines.end());
        return lines;
    };
    const ReadableStudyFile snapshot(uri_);
    const std::vector<std::string> expected = rows(path("station.db"));
    EXPECT_EQ(expected.size(), 1u + 2u * 35u);  // the header and each session's choices
    EXPECT_EQ(rows(snapshot.path()), expected);
}

}  // namespace
}  // namespace lucent::study
