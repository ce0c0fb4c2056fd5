// Withdrawals that stay withdrawn through merges (issue 26 item 2): the tombstones a
// withdrawal leaves, and merges of station files and backups that still hold the data.
#include "study/withdrawal.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "study/export.h"
#include "study/sha256.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;

int64_t count_of(const std::string& db_path, const std::string& sql) {
    return Database(db_path, SQLITE_OPEN_READONLY).scalar_int(sql);
}

class Withdrawal : public ::testing::Test {
protected:
    void SetUp() override { dir_ = lucent::test::scratch_dir("withdrawal"); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // One session of `code` on `machine`, every trial answered unless `answered` >= 0.
    std::string session(Store& store, const std::string& code, uint64_t seed,
                        const std::string& machine, int answered = -1) {
        const int64_t study = store.ensure_study(p_);
        int number = 0;
        const int64_t pid = store.ensure_participant(study, code, &number);
        SessionEnvironment env;
        env.machine_id = machine;
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p_, seed, number), seed, env);
        for (const TrialRow& t : store.trials(s.id)) {
            if (answered-- == 0) break;
            store.record_trial(s.id, t.id, lucent::test::outcome_for(p_, t));
        }
        return s.uuid;
    }
    Protocol p_ = lucent::test::small_protocol();
    fs::path dir_;
};

TEST_F(Withdrawal, WithdrawingLeavesTombstonesButNotTheCode) {
    const std::string db = path("study.db");
    std::string uuid;
    {
        Store store(db);
        uuid = session(store, "P07", 7, "machine-aaaa-0001");
        session(store, "P08", 8, "machine-aaaa-0001");
        EXPECT_TRUE(store.withdraw_participant("P07"));
        EXPECT_FALSE(store.withdraw_participant("P07"));  // nothing more is written
    }
    EXPECT_EQ(count_of(db, "SELECT count(*) FROM withdrawn_sessions"), 1);
    Database d(db, SQLITE_OPEN_READONLY);
    Statement s = d.prepare(
        "SELECT w.uuid, c.salt, c.code_hash FROM withdrawn_sessions w, "
        "withdrawn_codes c");
    ASSERT_TRUE(s.step());
    EXPECT_EQ(s.text(0), uuid);
    EXPECT_EQ(s.text(2), sha256_hex(s.text(1) + "P07\nmachine-aaaa-0001"));
    EXPECT_FALSE(s.step());  // one code row: one machine
    // The code itself is nowhere in the file's tombstones.
    EXPECT_EQ(
        d.scalar_int("SELECT count(*) FROM withdrawn_codes WHERE salt LIKE '%P07%' OR "
                     "code_hash LIKE '%P07%'"),
        0);
}

TEST_F(Withdrawal, MergingAStationFileDoesNotBringAWithdrawnParticipantBack) {
    // The station file still holds P01 and P02; the study file (a copy) withdrew P01.
    const std::string station = path("station.db"), study = path("study.db");
    {
        Store store(station);
        session(store, "P01", 1, "machine-aaaa-0001");
        session(store, "P02", 2, "machine-aaaa-0001");
    }
    fs::copy_file(station, study);
    Store(study).withdraw_participant("P01");
    for (const auto& inputs : {std::vector<std::string>{station, study},
                               std::vector<std::string>{study, station}}) {
        const std::string out = path(inputs[0] == station ? "a.db" : "b.db");
        const MergeReport report = merge_databases(inputs, out);
        EXPECT_EQ(report.sessions_withdrawn, 1);
        EXPECT_EQ(report.sessions_added, 1);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM sessions"), 1);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM participants WHERE code = 'P01'"),
                  0);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM participants WHERE code = 'P02'"),
                  1);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM responses"), 5 * 2);  // P02's only
        // The tombstones travel on, so the next merge of the station drops P01 again.
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM withdrawn_sessions"), 1);
        EXPECT_EQ(count_of(out, "SELECT count(*) FROM withdrawn_codes"), 1);
        EXPECT_EQ(
            count_of(out,
                     "SELECT count(*) FROM retired_participant_numbers WHERE number = 1"),
            1);
        const std::string again = out + ".again.db";
        EXPECT_EQ(merge_databases({station, out}, again).sessions_withdrawn, 1);
        EXPECT_EQ(count_of(again, "SELECT count(*) FROM participants WHERE code = 'P01'"),
                  0);
    }
}

TEST_F(Withdrawal, TheCodeHashDropsSessionsTheWithdrawingFileNeverSawButNotLaterOnes) {
    // The study file got P01's first session; the station went on with a second one
    // (before the withdrawal) and, after it, with a new P01: another person.
    const std::string station = path("station.db"), study = path("study.db");
    const std::string machine = "machine-aaaa-0001";
    {
        Store store(station);
        session(store, "P01", 1, machine, 2);
        store.db().exec("UPDATE sessions SET status = 'aborted'");
    }
    fs::copy_file(station, study);
    {
        Store store(station);
        session(store, "P01", 2, machine, 1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    Store(study).withdraw_participant("P01");
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::string later;
    {
        Store store(station);
        store.db().exec("UPDATE sessions SET status = 'aborted'");
        later = session(store, "P01", 3, machine);
    }
    const MergeReport report = merge_databases({station, study}, path("out.db"));
    EXPECT_EQ(report.sessions_withdrawn, 2);
    EXPECT_EQ(count_of(path("out.db"), "SELECT count(*) FROM sessions"), 1);
    Database out(path("out.db"), SQLITE_OPEN_READONLY);
    Statement s = out.prepare("SELECT uuid FROM sessions");
    ASSERT_TRUE(s.step());
    EXPECT_EQ(s.text(0), later);
    // The same code on another machine is someone else.
    const std::string other = path("other.db");
    {
        Store store(other);
        session(store, "P01", 4, "machine-bbbb-0002");
    }
    EXPECT_EQ(merge_databases({other, study}, path("out2.db")).sessions_withdrawn, 0);
    EXPECT_EQ(count_of(path("out2.db"), "SELECT count(*) FROM sessions"), 1);
}

TEST(EnrolledCode, MergedNamesLoseTheirMachineSuffixOnlyForTheirMachine) {
    EXPECT_EQ(enrolled_code("P07@3f2a9c1e", "3f2a9c1e0011"), "P07");
    EXPECT_EQ(enrolled_code("P07@3f2a9c1e#2", "3f2a9c1e0011"), "P07");
    EXPECT_EQ(enrolled_code("P07@unknown-machine", ""), "P07");
    EXPECT_EQ(enrolled_code("P07@3f2a9c1e", "77b0d2aa0011"), "P07@3f2a9c1e");
    EXPECT_EQ(enrolled_code("anna@lab", "lab"),
              "anna@lab");  // under 8 characters: a code
    EXPECT_TRUE(is_split_on_one_machine("P07@3f2a9c1e#2", "3f2a9c1e0011"));
    EXPECT_FALSE(is_split_on_one_machine("P07@3f2a9c1e", "3f2a9c1e0011"));
}

}  // namespace
}  // namespace lucent::study
