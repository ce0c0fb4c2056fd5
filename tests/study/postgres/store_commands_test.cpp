// The `lucent` commands on a server URI, run as the real binary against the suite's real
// PostgreSQL server: store init and sync, export, participants, merge and analyze. The
// reference for what a server export must hold is the same sessions written to an
// SQLite file (the long-established backend), exported by the same command.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

struct Ran {
    int exit_code = -1;
    std::string output;  // stdout and stderr
};

// Runs `lucent ARGS` (arguments are this file's constants and scratch paths).
Ran lucent(const std::vector<std::string>& args) {
    std::string command = "'" + std::string(LUCENT_EXECUTABLE) + "'";
    for (const std::string& a : args) command += " '" + a + "'";
    command += " 2>&1 </dev/null";
    Ran ran;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return ran;
    char buffer[4096];
    size_t n = 0;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) ran.output.append(buffer, n);
    const int status = pclose(pipe);
    ran.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return ran;
}

std::string read_file(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

class Commands : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = lucent::test::scratch_dir("commands_" + test);
        uri_ = lucent::test::new_postgres_database(test);
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
    // The same three deterministic sessions into `db`.
    void fill(const std::string& db) {
        auto store = open_study_store(db, options("fill"));
        const Protocol p = lucent::test::small_protocol();
        for (int k = 1; k <= 3; ++k) {
            const int64_t study = store->ensure_study(p);
            int number = 0;
            const std::string code = "P" + std::to_string(k);
            const int64_t pid = store->ensure_participant(study, code, &number);
            const SessionRow s =
                store->create_session(study, pid, plan_trials(p, k, number), k, {});
            for (const TrialRow& t : store->trials(s.id))
                store->record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
        }
    }
    std::filesystem::path dir_;
    std::string uri_;
};

TEST_F(Commands, StoreInitMigratesOnceAndExportMatchesTheSameSessionsInAFile) {
    const Ran init = lucent({"store", "init", "--db", uri_});
    EXPECT_EQ(init.exit_code, 0) << init.output;
    EXPECT_NE(init.output.find("schema 0 -> " + std::to_string(kSchemaVersion)),
              std::string::npos)
        << init.output;
    const Ran again = lucent({"store", "init", "--db", uri_});
    EXPECT_NE(again.output.find("up to date"), std::string::npos) << again.output;

    const std::string file = (dir_ / "reference.db").string();
    fill(uri_);
    fill(file);
    const auto from_server = dir_ / "server.csv", from_file = dir_ / "file.csv";
    const Ran a =
        lucent({"export", uri_, "--format", "analysis", "--out", from_server.string()});
    const Ran b =
        lucent({"export", file, "--format", "analysis", "--out", from_file.string()});
    ASSERT_EQ(a.exit_code, 0) << a.output;
    ASSERT_EQ(b.exit_code, 0) << b.output;
    const std::string server_csv = read_file(from_server);
    EXPECT_EQ(server_csv, read_file(from_file));
    // 3 participants x 3 rated stimuli x 2 questions, one factor each: 18 rows + header.
    EXPECT_EQ(std::count(server_csv.begin(), server_csv.end(), '\n'), 19) << server_csv;
}

TEST_F(Commands, AnalyzeReadsAServerAsItReadsTheSameSessionsInAFile) {
    init_study_store(uri_);
    fill(uri_);
    const std::string file = (dir_ / "reference.db").string();
    fill(file);
    const auto from_server = dir_ / "server_report", from_file = dir_ / "file_report";
    const Ran a =
        lucent({"analyze", uri_, "--out", from_server.string(), "--format", "csv"});
    const Ran b =
        lucent({"analyze", file, "--out", from_file.string(), "--format", "csv"});
    ASSERT_EQ(a.exit_code, 0) << a.output;
    ASSERT_EQ(b.exit_code, 0) << b.output;
    int compared = 0;
    for (const auto& entry : std::filesystem::directory_iterator(from_file)) {
        if (entry.path().extension() != ".csv") continue;
        EXPECT_EQ(read_file(from_server / entry.path().filename()),
                  read_file(entry.path()))
            << entry.path().filename();
        ++compared;
    }
    EXPECT_GT(compared, 0);
}

TEST_F(Commands, ParticipantsListAndWithdrawWorkOnAServer) {
    init_study_store(uri_);
    fill(uri_);
    const Ran list = lucent({"participants", "list", "--db", uri_});
    ASSERT_EQ(list.exit_code, 0) << list.output;
    for (const char* code : {"P1", "P2", "P3"})
        EXPECT_NE(list.output.find(std::string(code) + "  "), std::string::npos)
            << list.output;
    const Ran gone = lucent({"participants", "withdraw", "P2", "--db", uri_, "--yes"});
    EXPECT_EQ(gone.exit_code, 0) << gone.output;
    const Ran unknown = lucent({"participants", "withdraw", "P9", "--db", uri_, "--yes"});
    EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
    auto store = open_study_store(uri_, options("check"));
    EXPECT_FALSE(store->participant_counts("P2"));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM participants"), 2);
}

TEST_F(Commands, SyncSendsWhatAStoppedServerMissedAndNothingTwice) {
    init_study_store(uri_);
    const Protocol p = lucent::test::small_protocol();
    const std::string journal = options("station").journal_path;
    size_t planned = 0;
    {
        auto store = open_study_store(uri_, options("station"));
        const int64_t study = store->ensure_study(p);
        int number = 0;
        const int64_t pid = store->ensure_participant(study, "P4", &number);
        const SessionRow s =
            store->create_session(study, pid, plan_trials(p, 4, number), 4, {});
        const std::vector<TrialRow> trials = store->trials(s.id);
        planned = trials.size();
        store->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
        lucent::test::postgres_server().stop();
        for (size_t i = 1; i < trials.size(); ++i)  // the session runs on, journaled
            store->record_trial(s.id, trials[i].id,
                                lucent::test::outcome_for(p, trials[i]));
        EXPECT_EQ(store->pending_trials(), static_cast<int>(planned - 1));
    }  // the station closes with trials the server never saw
    const Ran offline = lucent({"store", "sync", "--db", uri_, "--journal", journal});
    EXPECT_EQ(offline.exit_code, 1) << offline.output;
    EXPECT_NE(offline.output.find("still held"), std::string::npos) << offline.output;
    lucent::test::postgres_server().start();
    const Ran sync = lucent({"store", "sync", "--db", uri_, "--journal", journal});
    EXPECT_EQ(sync.exit_code, 0) << sync.output;
    const std::string sent = "sent " + std::to_string(planned - 1) + " of " +
                             std::to_string(planned - 1) + " trials";
    EXPECT_NE(sync.output.find(sent), std::string::npos) << sync.output;
    const Ran twice = lucent({"store", "sync", "--db", uri_, "--journal", journal});
    EXPECT_NE(twice.output.find("sent 0 of 0"), std::string::npos) << twice.output;
    auto store = open_study_store(uri_, options("check"));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              static_cast<int64_t>(planned * p.questions.size()));
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
}

TEST_F(Commands, MergeReadsAServerAndAFileIntoOneFile) {
    init_study_store(uri_);
    fill(uri_);
    const std::string other = (dir_ / "other.db").string();
    {
        Store store(other);
        lucent::test::run_full_session(store, lucent::test::small_protocol(), "Q1", 11);
    }
    const std::string out = (dir_ / "merged.db").string();
    const Ran merged = lucent({"merge", uri_, other, "--out", out});
    ASSERT_EQ(merged.exit_code, 0) << merged.output;
    EXPECT_EQ(
        Database(out, SQLITE_OPEN_READONLY).scalar_int("SELECT count(*) FROM sessions"),
        4);
}

TEST_F(Commands, MergeIntoAServerAddsOnlyWhatItLacksAndMatchesAMergedFile) {
    init_study_store(uri_);
    fill(uri_);
    const std::string other = (dir_ / "other.db").string(),
                      copy = (dir_ / "copy.db").string();
    {
        Store store(other);
        lucent::test::run_full_session(store, lucent::test::small_protocol(), "Q1", 11);
        lucent::test::run_full_session(store, lucent::test::small_protocol(), "Q2", 12);
    }
    open_study_store(uri_, options("x"))
        ->snapshot_to_sqlite(copy);  // the server's 3 again
    // The reference: the same inputs merged into a file.
    const std::string file = (dir_ / "merged.db").string();
    ASSERT_EQ(lucent({"merge", copy, other, "--out", file}).exit_code, 0);

    const Ran into = lucent({"merge", other, copy, "--out", uri_});
    ASSERT_EQ(into.exit_code, 0) << into.output;
    EXPECT_NE(into.output.find("2 sessions added, 3 already there"), std::string::npos)
        << into.output;
    const Ran again = lucent({"merge", other, "--out", uri_});
    EXPECT_NE(again.output.find("0 sessions added, 2 already there"), std::string::npos)
        << again.output;
    const auto a = dir_ / "server.csv", b = dir_ / "file.csv";
    ASSERT_EQ(lucent({"export", uri_, "--format", "long", "--out", a.string()}).exit_code,
              0);
    ASSERT_EQ(lucent({"export", file, "--format", "long", "--out", b.string()}).exit_code,
              0);
    // Long rows name the session UUID, trial position, ratings and provenance of each
    // row.
    EXPECT_EQ(read_file(a), read_file(b));
    auto store = open_study_store(uri_, options("check"));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM sessions"), 5);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials WHERE uuid IS NULL"), 0);
    // A code the server holds, from another machine: refused, nothing changed.
    const std::string clash = (dir_ / "clash.db").string();
    {
        Store store(clash);
        const Protocol p = lucent::test::small_protocol();
        const int64_t study = store.ensure_study(p);
        const int64_t pid = store.ensure_participant(study, "P1", nullptr);
        SessionEnvironment env;
        env.machine_id = "another-machine";
        store.create_session(study, pid, plan_trials(p, 1, 1), 1, env);
    }
    const Ran refused = lucent({"merge", clash, "--out", uri_});
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_EQ(store->query_int("SELECT count(*) FROM sessions"), 5);
}

TEST_F(Commands, BadServerArgumentsExitTwoWithOneLine) {
    const Ran password = lucent({"export", "postgresql://anna:secret@localhost/study",
                                 "--out", (dir_ / "x.csv").string()});
    EXPECT_EQ(password.exit_code, 2) << password.output;
    EXPECT_NE(password.output.find("PGPASSWORD"), std::string::npos) << password.output;
    EXPECT_EQ(std::count(password.output.begin(), password.output.end(), '\n'), 1)
        << password.output;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "x.csv"));
    const Ran scheme = lucent({"store", "init", "--db", "mysql://anna@localhost/study"});
    EXPECT_EQ(scheme.exit_code, 2) << scheme.output;
    const Ran uninitialised = lucent({"participants", "list", "--db", uri_});
    EXPECT_EQ(uninitialised.exit_code, 2) << uninitialised.output;
    EXPECT_NE(uninitialised.output.find("lucent store init"), std::string::npos)
        << uninitialised.output;
}

}  // namespace
}  // namespace lucent::study
