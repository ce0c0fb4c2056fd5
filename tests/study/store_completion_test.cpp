// Completion is atomic and final: the last trial's ratings and the status `completed` are
// one transaction, whichever write fails, and nothing reopens a completed session.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "study/sqlite/sqlite_store.h"
#include "tests/study/faulty_vfs.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;
using lucent::test::outcome_for;
using lucent::test::small_protocol;

// A session with every trial but the last answered.
SessionRow almost_done(Store& store, const Protocol& p) {
    const int64_t study = store.ensure_study(p);
    const int64_t pid = store.ensure_participant(study, "P1", nullptr);
    const SessionRow s = store.create_session(study, pid, plan_trials(p, 4, 1), 4, {});
    const std::vector<TrialRow> trials = store.trials(s.id);
    for (size_t i = 0; i + 1 < trials.size(); ++i)
        EXPECT_FALSE(store.record_trial(s.id, trials[i].id, outcome_for(p, trials[i])));
    return s;
}

TEST(StoreCompletion, TheLastTrialCompletesTheSessionInItsTransaction) {
    const auto dir = lucent::test::scratch_dir("completion_last");
    Store store((dir / "s.db").string());
    const Protocol p = small_protocol();
    const SessionRow s = almost_done(store, p);
    EXPECT_EQ(
        store.db().scalar_int("SELECT count(*) FROM sessions WHERE status = 'running' "
                              "AND ended_utc IS NULL"),
        1);
    EXPECT_TRUE(store.record_trial(s.id, store.trials(s.id).back().id,
                                   outcome_for(p, store.trials(s.id).back())));
    EXPECT_EQ(
        store.db().scalar_int("SELECT count(*) FROM sessions WHERE status = 'completed' "
                              "AND ended_utc IS NOT NULL"),
        1);
    EXPECT_FALSE(store.unfinished_session("P1").has_value());
    EXPECT_TRUE(store.has_completed_session("P1"));
}

TEST(StoreCompletion, ACompletedSessionIsNeverReopened) {
    const auto dir = lucent::test::scratch_dir("completion_final");
    Store store((dir / "s.db").string());
    const int64_t id = lucent::test::run_full_session(store, small_protocol(), "P1", 1);
    for (const char* status : {"paused", "running", "aborted"}) {
        EXPECT_THROW(store.set_status(id, status, false), StoreError) << status;
    }
    store.set_status(id, "completed", true);  // saying it again is harmless
    EXPECT_EQ(
        store.db().scalar_int("SELECT count(*) FROM sessions WHERE status = 'completed' "
                              "AND ended_utc IS NOT NULL"),
        1);
}

TEST(StoreCompletion, AnsweredButOpenSessionsFromOlderBuildsAreRepaired) {
    const auto dir = lucent::test::scratch_dir("completion_repair");
    Store store((dir / "s.db").string());
    const Protocol p = small_protocol();
    const SessionRow s = almost_done(store, p);
    EXPECT_FALSE(store.complete_session_if_answered(s.id));
    store.record_trial(s.id, store.trials(s.id).back().id,
                       outcome_for(p, store.trials(s.id).back()));
    // What Escape on the debrief did before: completed turned back into paused.
    store.db().exec("UPDATE sessions SET status = 'paused', ended_utc = NULL");
    EXPECT_TRUE(store.complete_session_if_answered(s.id));
    EXPECT_EQ(
        store.db().scalar_int("SELECT count(*) FROM sessions WHERE status = 'completed' "
                              "AND ended_utc IS NOT NULL"),
        1);
}

TEST(StoreCompletion, FailingAnyWriteOfTheLastTrialLeavesItAllOrNothing) {
    lucent::test::FaultyVfs::install();
    const auto dir = lucent::test::scratch_dir("completion_fault");
    const Protocol p = small_protocol();
    const fs::path baseline = dir / "baseline.db";
    {
        Store store(baseline.string());
        almost_done(store, p);
    }
    int faults = 0;
    for (int n = 1; n < 200; ++n) {
        const fs::path path = dir / "work.db";
        for (const char* suffix : {"", "-wal", "-shm"})
            fs::remove(path.string() + suffix);
        fs::copy_file(baseline, path);
        bool failed = false;
        {
            Store store(path.string(), lucent::test::FaultyVfs::kName);
            const SessionRow s = *store.unfinished_session("P1");
            const TrialRow last = store.trials(s.id).back();
            lucent::test::FaultyVfs::reset();
            lucent::test::FaultyVfs::fail_write(n);
            try {
                store.record_trial(s.id, last.id, outcome_for(p, last));
            } catch (const StoreError&) {
                failed = true;
            }
            lucent::test::FaultyVfs::fail_write(0);
        }
        // Reopened as after a crash: the last trial answered if and only if completed.
        Database db(path.string(), SQLITE_OPEN_READONLY);
        const int64_t open_trials = db.scalar_int(
            "SELECT count(*) FROM trials t WHERE NOT EXISTS "
            "(SELECT 1 FROM responses r WHERE r.trial_id = t.id)");
        const int64_t completed = db.scalar_int(
            "SELECT count(*) FROM sessions WHERE status = 'completed' AND ended_utc IS "
            "NOT NULL");
        EXPECT_EQ(open_trials == 0, completed == 1)
            << "write " << n << ": " << open_trials << " open trials, completed "
            << completed;
        EXPECT_EQ(open_trials + completed, 1) << "write " << n;
        if (!failed) break;
        ++faults;
    }
    std::printf("last trial: %d distinct writes failed, each all or nothing\n", faults);
    EXPECT_GT(faults, 2) << "too few writes of the last trial were failed";
}

}  // namespace
}  // namespace lucent::study
