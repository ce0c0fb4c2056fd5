// Fault tests in the manner of SQLite's own: *fault (fail the Nth write), crash (SIGKILL
// mid-session, then resume) and corrupt (foreign and damaged files are refused and left
// byte-for-byte unchanged).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <thread>

#include "study/sha256.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/faulty_vfs.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;
using lucent::test::small_protocol;

std::string file_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// Every trial holds all of its ratings or none, and the database is intact.
void expect_consistent(Database& db, int questions) {
    Statement check = db.prepare("PRAGMA integrity_check");
    ASSERT_TRUE(check.step());
    EXPECT_EQ(check.text(0), "ok");
    EXPECT_EQ(
        db.scalar_int("SELECT count(*) FROM (SELECT trial_id, count(*) c FROM responses "
                      "GROUP BY trial_id HAVING c != " +
                      std::to_string(questions) + ")"),
        0);
}

// A session with many trials, so that kills land at random places.
Protocol long_protocol() {
    std::string text = lucent::test::kSmallProtocol;
    text.replace(text.find("id = \"main\""), 11, "id = \"main\"\nrepeats = 15");
    return parse_protocol(text, "long.toml");
}

// Answers every unanswered trial of the participant's unfinished session.
// The last trial completes the session in its own transaction.
void finish_session(Store& store, const Protocol& p, const std::string& code) {
    const auto s = store.unfinished_session(code);
    if (s) {
        for (const TrialRow& t : store.trials(s->id))
            if (!t.answered)
                store.record_trial(s->id, t.id, lucent::test::outcome_for(p, t));
    }
    EXPECT_FALSE(store.unfinished_session(code).has_value());
    EXPECT_TRUE(store.has_completed_session(code));
}

TEST(StoreFault, FailingTheNthWriteNeverLosesOrSplitsATrial) {
    lucent::test::FaultyVfs::install();
    const auto dir = lucent::test::scratch_dir("store_fault");
    const fs::path baseline = dir / "baseline.db";
    const Protocol p = small_protocol();
    const int questions = static_cast<int>(p.questions.size());
    {
        Store store(baseline.string());
        const int64_t study = store.ensure_study(p);
        const int64_t pid = store.ensure_participant(study, "P1", nullptr);
        store.create_session(study, pid, plan_trials(p, 3, 1), 3, {});
    }
    int faults = 0;
    for (int n = 1; n < 500; ++n) {
        const fs::path path = dir / "work.db";
        fs::remove(path);
        fs::remove(path.string() + "-wal");
        fs::remove(path.string() + "-shm");
        fs::copy_file(baseline, path);
        int committed = 0;
        bool failed = false;
        {
            Store store(path.string(), lucent::test::FaultyVfs::kName);
            const auto s = store.unfinished_session("P1");
            lucent::test::FaultyVfs::reset();
            lucent::test::FaultyVfs::fail_write(n);
            try {
                for (const TrialRow& t : store.trials(s->id)) {
                    store.record_trial(s->id, t.id, lucent::test::outcome_for(p, t));
                    ++committed;
                }
            } catch (const StoreError& e) {
                failed = true;
                EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
            }
            lucent::test::FaultyVfs::fail_write(0);
        }
        Store store(path.string());
        expect_consistent(store.db(), questions);
        const int64_t answered =
            store.db().scalar_int("SELECT count(DISTINCT trial_id) FROM responses");
        EXPECT_GE(answered, committed) << "write " << n << ": a committed trial was lost";
        EXPECT_LE(answered, committed + 1) << "write " << n;
        // Resuming completes the session with exactly one rating per (trial, question).
        finish_session(store, p, "P1");
        EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"),
                  store.db().scalar_int("SELECT count(*) FROM trials") * questions);
        expect_consistent(store.db(), questions);
        if (!failed)
            break;  // the whole session ran before write n: every write was tried
        ++faults;
    }
    EXPECT_GT(faults, 5) << "the fault loop should have failed several distinct writes";
}

TEST(StoreCrash, SigkillMidSessionThenResumeKeepsEveryRatingOnce) {
    const auto dir = lucent::test::scratch_dir("store_crash");
    const Protocol p = long_protocol();
    const int questions = static_cast<int>(p.questions.size());
    std::mt19937 gen(2024);
    for (int round = 0; round < 4; ++round) {
        const std::string path =
            (dir / ("crash" + std::to_string(round) + ".db")).string();
        {
            Store store(path);
            const int64_t study = store.ensure_study(p);
            const int64_t pid = store.ensure_participant(study, "P1", nullptr);
            store.create_session(study, pid, plan_trials(p, round, 1), round, {});
        }
        const pid_t child = fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            // The child records trials slowly until it is killed.
            Store store(path);
            const auto s = store.unfinished_session("P1");
            for (const TrialRow& t : store.trials(s->id)) {
                store.record_trial(s->id, t.id, lucent::test::outcome_for(p, t));
                std::this_thread::sleep_for(std::chrono::milliseconds(2));
            }
            _exit(0);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(15 + gen() % 50));
        kill(child, SIGKILL);
        int status = 0;
        waitpid(child, &status, 0);
        Store store(path);
        expect_consistent(store.db(), questions);
        const int64_t before = store.db().scalar_int("SELECT count(*) FROM responses");
        finish_session(store, p, "P1");
        EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"),
                  store.db().scalar_int("SELECT count(*) FROM trials") * questions);
        EXPECT_EQ(store.db().scalar_int(
                      "SELECT count(*) FROM (SELECT trial_id, question, "
                      "count(*) c FROM responses GROUP BY 1, 2 HAVING c > 1)"),
                  0);
        RecordProperty("kept_before_resume_" + std::to_string(round),
                       std::to_string(before));
    }
}

struct CorruptCase {
    std::string name;
    std::function<void(const fs::path&)> make;
    std::string expect;
};

TEST(StoreCorrupt, ForeignAndDamagedFilesAreRefusedAndUnchanged) {
    const auto dir = lucent::test::scratch_dir("store_corrupt");
    // A healthy study database to damage.
    const fs::path good = dir / "good.db";
    {
        Store store(good.string());
        lucent::test::run_full_session(store, small_protocol(), "P1", 1);
    }
    ASSERT_FALSE(fs::exists(good.string() + "-wal"));
    const std::string good_bytes = file_bytes(good);
    ASSERT_GT(good_bytes.size(), 4096u * 3);

    const CorruptCase cases[] = {
        {"random_bytes",
         [](const fs::path& p) {
             std::ofstream out(p, std::ios::binary);
             std::mt19937 g(1);
             for (int i = 0; i < 10000; ++i) out.put(static_cast<char>(g()));
         },
         "not a Lucent study database"},
        {"png_file",
         [](const fs::path& p) {
             std::ofstream(p, std::ios::binary) << "\x89PNG\r\n\x1a\n rest";
         },
         "not an SQLite file"},
        {"other_application",
         [](const fs::path& p) {
             Database db(p.string(), SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
             db.exec("CREATE TABLE notes (x TEXT); INSERT INTO notes VALUES ('mine')");
         },
         "application_id 0x00000000"},
        {"newer_schema",
         [&](const fs::path& p) {
             fs::copy_file(good, p);
             Database db(p.string(), SQLITE_OPEN_READWRITE);
             db.exec("PRAGMA journal_mode = DELETE; PRAGMA user_version = 99");
         },
         "newer Lucent"},
        {"damaged_pages",
         [&](const fs::path& p) {
             std::string bytes = good_bytes;
             for (size_t i = 4096 + 50; i < bytes.size(); i += 7) bytes[i] = '\xA5';
             std::ofstream(p, std::ios::binary) << bytes;
         },
         "corrupt"},
        {"truncated",
         [&](const fs::path& p) {
             std::ofstream(p, std::ios::binary)
                 << good_bytes.substr(0, good_bytes.size() / 2);
         },
         "corrupt"},
    };
    for (const CorruptCase& c : cases) {
        const fs::path path = dir / (c.name + ".db");
        c.make(path);
        for (const char* suffix : {"-wal", "-shm"}) fs::remove(path.string() + suffix);
        const std::string before = sha256_hex(file_bytes(path));
        try {
            Store store(path.string());
            ADD_FAILURE() << c.name << ": opened without error";
        } catch (const StoreError& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find(c.expect), std::string::npos)
                << c.name << ": " << message;
            EXPECT_NE(message.find(path.string()), std::string::npos) << message;
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        }
        EXPECT_EQ(sha256_hex(file_bytes(path)), before) << c.name << " was modified";
        EXPECT_FALSE(fs::exists(path.string() + "-wal")) << c.name;
    }
}

}  // namespace
}  // namespace lucent::study
