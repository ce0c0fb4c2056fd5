// The study store: pragmas, schema version and migration, planned order written before
// trial 1, one transaction per trial, resume and withdrawal.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <memory>
#include <thread>

#include "study/export.h"
#include "study/observations.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::kSmallProtocol;
using lucent::test::small_protocol;

TEST(Store, OpensWithWalFullSyncAndForeignKeys) {
    const auto dir = lucent::test::scratch_dir("store_pragmas");
    Store store((dir / "s.db").string());
    Database& db = store.db();
    Statement mode = db.prepare("PRAGMA journal_mode");
    ASSERT_TRUE(mode.step());
    EXPECT_EQ(mode.text(0), "wal");
    EXPECT_EQ(db.scalar_int("PRAGMA synchronous"), 2);  // FULL
    EXPECT_EQ(db.scalar_int("PRAGMA foreign_keys"), 1);
    EXPECT_EQ(db.scalar_int("PRAGMA application_id"), kApplicationId);
    EXPECT_EQ(db.scalar_int("PRAGMA user_version"), kSchemaVersion);
}

TEST(Store, WritesTheWholePlanBeforeTheFirstTrial) {
    const auto dir = lucent::test::scratch_dir("store_plan");
    Store store((dir / "s.db").string());
    const Protocol p = small_protocol();
    const int64_t study = store.ensure_study(p);
    int number = -1;
    const int64_t pid = store.ensure_participant(study, "P7", &number);
    EXPECT_EQ(number, 7);
    const TrialPlan plan = plan_trials(p, 42, number);
    const SessionRow s = store.create_session(study, pid, plan, 42, {});
    const std::vector<TrialRow> trials = store.trials(s.id);
    ASSERT_EQ(trials.size(), plan.trials.size());
    for (size_t i = 0; i < trials.size(); ++i) {
        EXPECT_EQ(trials[i].stimulus, plan.trials[i].stimulus);
        EXPECT_EQ(trials[i].practice, plan.trials[i].practice);
        EXPECT_EQ(trials[i].is_catch, plan.trials[i].is_catch);
        EXPECT_FALSE(trials[i].answered);
    }
    EXPECT_EQ(s.uuid.size(), 36u);
    EXPECT_EQ(s.uuid[14], '4');
    // Stimulus parameters are stored as rows, ready to serve as factors.
    EXPECT_EQ(
        store.db().scalar_int(
            "SELECT count(*) FROM stimulus_parameters p JOIN stimuli s ON s.id = "
            "p.stimulus_id WHERE s.stimulus_key = 'b' AND p.name = 'thickness_exponent' "
            "AND p.value = '25'"),
        1);
}

TEST(Store, RecordsEachTrialOnceAndRefusesDuplicates) {
    const auto dir = lucent::test::scratch_dir("store_record");
    Store store((dir / "s.db").string());
    const Protocol p = small_protocol();
    const int64_t study = store.ensure_study(p);
    const int64_t pid = store.ensure_participant(study, "anna", nullptr);
    const SessionRow s = store.create_session(study, pid, plan_trials(p, 1, 1), 1, {});
    const std::vector<TrialRow> trials = store.trials(s.id);
    store.record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
    EXPECT_THROW(
        store.record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0])),
        StoreError);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"), 2);
    // A rating outside 1..7 violates the CHECK constraint and leaves nothing behind.
    TrialOutcome bad = lucent::test::outcome_for(p, trials[1]);
    bad.responses[1].rating = 8;
    EXPECT_THROW(store.record_trial(s.id, trials[1].id, bad), StoreError);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"), 2);
    EXPECT_TRUE(store.trials(s.id)[0].answered);
    EXPECT_FALSE(store.trials(s.id)[1].answered);
}

TEST(Store, ResumeFindsTheUnfinishedSessionWithItsOrder) {
    const auto dir = lucent::test::scratch_dir("store_resume");
    const std::string path = (dir / "s.db").string();
    const Protocol p = small_protocol();
    std::vector<std::string> order;
    {
        Store store(path);
        const int64_t study = store.ensure_study(p);
        const int64_t pid = store.ensure_participant(study, "P2", nullptr);
        const SessionRow s =
            store.create_session(study, pid, plan_trials(p, 9, 2), 9, {});
        const auto trials = store.trials(s.id);
        for (const auto& t : trials) order.push_back(t.stimulus);
        store.record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
        store.record_trial(s.id, trials[1].id, lucent::test::outcome_for(p, trials[1]));
    }
    Store store(path);
    const auto s = store.unfinished_session("P2");
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->seed, 9u);
    const auto trials = store.trials(s->id);
    std::vector<std::string> again;
    for (const auto& t : trials) again.push_back(t.stimulus);
    EXPECT_EQ(again, order);
    EXPECT_TRUE(trials[1].answered);
    EXPECT_FALSE(trials[2].answered);
    EXPECT_FALSE(store.unfinished_session("nobody").has_value());
}

TEST(Store, RefusesASecondProtocolInOneDatabase) {
    const auto dir = lucent::test::scratch_dir("store_two_protocols");
    Store store((dir / "s.db").string());
    store.ensure_study(small_protocol());
    EXPECT_THROW(store.ensure_study(builtin_protocol("thesis")), StoreError);
    EXPECT_EQ(store.ensure_study(small_protocol()), store.ensure_study(small_protocol()));
}

TEST(Store, WithdrawDeletesEverythingOfThatParticipantOnly) {
    const auto dir = lucent::test::scratch_dir("store_withdraw");
    Store store((dir / "s.db").string());
    const Protocol p = small_protocol();
    lucent::test::run_full_session(store, p, "P1", 1);
    lucent::test::run_full_session(store, p, "P2", 2);
    const int64_t per_session =
        store.db().scalar_int("SELECT count(*) FROM responses") / 2;
    EXPECT_TRUE(store.withdraw_participant("P1"));
    EXPECT_FALSE(store.withdraw_participant("P1"));
    Database& db = store.db();
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM participants WHERE code = 'P1'"), 0);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM sessions"), 1);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM responses"), per_session);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM trials t LEFT JOIN sessions s ON "
                            "s.id = t.session_id WHERE s.id IS NULL"),
              0);
}

TEST(Store, EnrolmentNumbersAreNeverSharedAfterAWithdrawal) {
    const auto dir = lucent::test::scratch_dir("store_enrolment_numbers");
    Store store((dir / "s.db").string());
    const Protocol p = small_protocol();
    const int64_t study = store.ensure_study(p);
    auto number_of = [&](const std::string& code) {
        int n = -1;
        store.ensure_participant(study, code, &n);
        return n;
    };
    EXPECT_EQ(number_of("anna"), 1);
    EXPECT_EQ(number_of("bob"), 2);
    EXPECT_EQ(number_of("carl"), 3);
    ASSERT_TRUE(store.withdraw_participant("anna"));
    // Two participants remain (numbers 2 and 3): the next is 4, not a second 3.
    EXPECT_EQ(number_of("dave"), 4);
    EXPECT_EQ(number_of("P7"), 7);  // trailing digits choose the number
    EXPECT_EQ(number_of("eve"), 8);
    EXPECT_EQ(number_of("bob"), 2);  // known codes keep theirs
    EXPECT_EQ(store.db().scalar_int("SELECT count(DISTINCT number) FROM participants"),
              store.db().scalar_int("SELECT count(*) FROM participants"));
    // Withdrawing the newest participant retires their number too: eve had 8, so the
    // next enrolment is 9, never a second 8 (and a second Latin-square row 8).
    ASSERT_TRUE(store.withdraw_participant("eve"));
    EXPECT_EQ(number_of("fay"), 9);
    ASSERT_TRUE(store.withdraw_participant("fay"));
    ASSERT_TRUE(store.withdraw_participant("P7"));
    EXPECT_EQ(number_of("gus"), 10);
}

TEST(Store, MigratesAVersion1DatabaseKeepingItsRows) {
    const auto dir = lucent::test::scratch_dir("store_migrate");
    const std::string path = (dir / "old.db").string();
    {
        Database db(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        migrate(db, 1);
        db.exec(
            "INSERT INTO studies (name, protocol_text, protocol_hash, created_utc) "
            "VALUES ('old', 'x', 'h', 'now')");
        ASSERT_EQ(db.scalar_int("PRAGMA user_version"), 1);
    }
    Store store(path);
    EXPECT_EQ(store.db().scalar_int("PRAGMA user_version"), kSchemaVersion);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM studies WHERE name = 'old'"),
              1);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM pragma_table_info('sessions') "
                                    "WHERE name = 'refresh_note'"),
              1);
}

// Schema 9 (issue 44) on a file an older build left at schema 8: declined_codes added,
// the per-page count and the declined pages of schema 8 kept (and still read), every
// answer kept; the sessions note names both counts for what they are.
TEST(Store, MigratesASchema8DatabaseKeepingItsPageDeclinesBesideTheNewCodes) {
    const auto dir = lucent::test::scratch_dir("store_migrate_8");
    const std::string path = (dir / "old.db").string();
    const Protocol p = lucent::test::small_protocol();
    int64_t responses = 0;
    {
        Store store(path);
        lucent::test::run_full_session(store, p, "P1", 3);
        Database& db = store.db();
        responses = db.scalar_int("SELECT count(*) FROM responses");
        db.exec(
            "INSERT INTO consent_declines (study_id, declined) VALUES (1, 401); "
            "INSERT INTO declined_pages (uuid) VALUES ('old-page')");
        lucent::test::downgrade_schema(db, 8);
        ASSERT_EQ(db.scalar_int(
                      "SELECT count(*) FROM sqlite_schema WHERE name = 'declined_codes'"),
                  0);
    }
    {
        Database old(path, SQLITE_OPEN_READONLY);  // read as it is: the page count alone
        EXPECT_EQ(declined_consent_figure(old),
                  "401 consent declines counted per page before schema 9 (page loads, "
                  "not people)");
    }
    Store store(path);
    Database& db = store.db();
    EXPECT_EQ(db.scalar_int("PRAGMA user_version"), kSchemaVersion);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM responses"), responses);
    EXPECT_EQ(db.scalar_int("SELECT declined FROM consent_declines"), 401);
    EXPECT_TRUE(store.consent_declined("old-page"));
    EXPECT_TRUE(store.decline_consent(1, "P2", "new-page"));
    EXPECT_FALSE(store.decline_consent(1, "P2", "newer-page"));
    EXPECT_EQ(db.scalar_int("SELECT declined FROM consent_declines"), 401);
    EXPECT_EQ(declined_consent_figure(db),
              "1 participant code declined consent, and 401 consent declines counted "
              "per page before schema 9 (page loads, not people)");
}

// Schema 10 on a file an older build left at schema 9: trials.kind's CHECK of the six
// built-in names is gone (a kind is a registry entry), no row moved, and a kind this
// build does not know is refused when read, never taken for another.
TEST(Store, MigratesASchema9DatabaseDroppingTheKindCheckAndRefusesAnUnknownKind) {
    const auto dir = lucent::test::scratch_dir("store_migrate_9");
    const std::string path = (dir / "old.db").string();
    const Protocol p = lucent::test::choice_protocol();
    int64_t trials = 0, responses = 0, session = 0;
    auto trials_sql = [](Database& db) {
        Statement s = db.prepare("SELECT sql FROM sqlite_schema WHERE name = 'trials'");
        return s.step() ? s.text(0) : std::string();
    };
    {
        Store store(path);
        session = lucent::test::run_full_session(store, p, "P1", 3);
        Database& db = store.db();
        trials = db.scalar_int("SELECT count(*) FROM trials");
        responses = db.scalar_int("SELECT count(*) FROM responses");
        lucent::test::downgrade_schema(db, 9);
        ASSERT_NE(trials_sql(db).find("CHECK (kind IN"), std::string::npos);
        EXPECT_THROW(db.exec("UPDATE trials SET kind = 'probe' WHERE id = 1"),
                     StoreError);
    }
    Store store(path);
    Database& db = store.db();
    EXPECT_EQ(db.scalar_int("PRAGMA user_version"), kSchemaVersion);
    EXPECT_EQ(trials_sql(db).find("CHECK (kind IN"), std::string::npos) << trials_sql(db);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM trials"), trials);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM responses"), responses);
    {
        Statement check = db.prepare("PRAGMA integrity_check");
        ASSERT_TRUE(check.step());
        EXPECT_EQ(check.text(0), "ok");
    }
    // The other CHECKs stay (skipped's, task's).
    EXPECT_THROW(db.exec("UPDATE trials SET skipped = 2 WHERE id = 1"), StoreError);
    const int64_t answered = db.scalar_int(
        "SELECT min(t.id) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE "
        "t.session_id = " +
        std::to_string(session) + " AND t.kind = 'pair'");
    db.exec("UPDATE trials SET kind = 'probe' WHERE id = " + std::to_string(answered));
    try {
        store.trials(session);
        ADD_FAILURE() << "a trial of an unknown kind was read";
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("kind is 'probe', which this build does not "
                                             "know"),
                  std::string::npos)
            << e.what();
    }
    try {
        read_observations(path, {});
        ADD_FAILURE() << "an observation of an unknown kind was read";
    } catch (const StoreError& e) {
        EXPECT_NE(
            std::string(e.what()).find("has kind 'probe', which this build does not "
                                       "know"),
            std::string::npos)
            << e.what();
    }
}

// Schema 7 (issue 31) on a file an older build left at schema 6: trials.kind filled from
// trials.task (NULL, a trial planned before schema 6: a rating), the new columns empty,
// every answer kept; the readers then read kind.
TEST(Store, MigratesASchema6DatabaseFillingEachTrialsKindFromItsTask) {
    const auto dir = lucent::test::scratch_dir("store_migrate_6");
    const std::string path = (dir / "old.db").string();
    const Protocol p = lucent::test::choice_protocol();
    std::map<std::string, int64_t> by_task;  // as written, before the downgrade
    int64_t trials = 0, responses = 0, session = 0;
    std::vector<TrialRow> before;
    {
        Store store(path);
        session = lucent::test::run_full_session(store, p, "P1", 3);
        before = store.trials(session);
        Database& db = store.db();
        trials = db.scalar_int("SELECT count(*) FROM trials");
        responses = db.scalar_int("SELECT count(*) FROM responses");
        Statement s = db.prepare("SELECT task, count(*) FROM trials GROUP BY task");
        while (s.step()) by_task[s.text(0)] = s.integer(1);
        lucent::test::downgrade_schema(db, 6);
        // One rating planned before schema 6: no task.
        db.exec(
            "UPDATE trials SET task = NULL WHERE id = (SELECT min(id) FROM trials WHERE "
            "task = 'rating')");
        ASSERT_EQ(db.scalar_int("SELECT count(*) FROM pragma_table_info('trials') WHERE "
                                "name = 'kind'"),
                  0);
    }
    ASSERT_GT(by_task["pair"], 0);
    ASSERT_GT(by_task["triad"], 0);
    ASSERT_GT(by_task["rating"], 1);
    Store store(path);
    Database& db = store.db();
    EXPECT_EQ(db.scalar_int("PRAGMA user_version"), kSchemaVersion);
    {
        // kind = coalesce(task, 'rating'): the counts per task as written.
        Statement s = db.prepare("SELECT kind, count(*) FROM trials GROUP BY kind");
        std::map<std::string, int64_t> by_kind;
        while (s.step()) by_kind[s.is_null(0) ? "(null)" : s.text(0)] = s.integer(1);
        EXPECT_EQ(by_kind, by_task);
    }
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM trials WHERE task IS NULL AND kind = "
                            "'rating'"),
              1);
    EXPECT_EQ(
        db.scalar_int("SELECT count(*) FROM trials WHERE start_value IS NOT NULL OR "
                      "final_value IS NOT NULL OR staircase IS NOT NULL OR "
                      "intensity IS NOT NULL OR skipped <> 0"),
        0);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM trials"), trials);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM responses"), responses);
    EXPECT_EQ(db.scalar_int("SELECT count(*) FROM adjustments"), 0);
    const std::vector<TrialRow> after = store.trials(session);
    ASSERT_EQ(after.size(), before.size());
    for (size_t i = 0; i < after.size(); ++i) {
        EXPECT_EQ(after[i].task, before[i].task) << i;
        EXPECT_EQ(after[i].answered, before[i].answered) << i;
        EXPECT_EQ(after[i].choice, before[i].choice) << i;
    }
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

// Another process holding the file a moment (here: exclusive locking mode for 300 ms)
// is waited for; before, the read-only check named such a database corrupt.
TEST(Store, ABusyDatabaseIsWaitedForNotCalledCorrupt) {
    const auto dir = lucent::test::scratch_dir("store_busy");
    const std::string path = (dir / "s.db").string();
    { Store store(path); }
    auto holder = std::make_unique<Database>(path, SQLITE_OPEN_READWRITE);
    holder->exec("PRAGMA locking_mode = EXCLUSIVE");
    holder->exec("BEGIN EXCLUSIVE");
    holder->exec("COMMIT");  // the exclusive lock stays until the connection closes
    std::thread release([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        holder.reset();
    });
    EXPECT_NO_THROW(check_database_file(path));
    release.join();
}

}  // namespace
}  // namespace lucent::study
