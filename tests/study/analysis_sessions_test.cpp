// Issue 26 item 3: which sessions the analysis long table (`export --format analysis`,
// `lucent analyze study.db`) takes. Completed sessions by default, so a participant who
// gave up, or quit before the catch trials, no longer enters the analysis unchecked; the
// sessions left out are counted by reason (incomplete, failed catch trials, withdrawn).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "study/export.h"
#include "study/observations.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;

// Answers the session's trials in order until `rated` non-practice, non-catch trials
// are answered (the catch trial only if it comes before them), then leaves the session
// with `status`. Returns how many rated (non-practice, non-catch) trials it answered.
int run_partial_session(Store& store, const Protocol& p, const std::string& code,
                        uint64_t seed, int rated, const std::string& status) {
    const int64_t study_id = store.ensure_study(p);
    int number = 0;
    const int64_t pid = store.ensure_participant(study_id, code, &number);
    const SessionRow s =
        store.create_session(study_id, pid, plan_trials(p, seed, number), seed, {});
    int answered = 0;
    for (const TrialRow& t : store.trials(s.id)) {
        if (answered == rated) break;
        store.record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
        if (!t.practice && !t.is_catch) ++answered;
    }
    if (status != "running") store.set_status(s.id, status, status != "paused");
    return answered;
}

std::string uuid_of(const std::string& path, int64_t session_id) {
    Database db(path, SQLITE_OPEN_READONLY);
    Statement s = db.prepare("SELECT uuid FROM sessions WHERE id = ?");
    s.bind(1, session_id);
    EXPECT_TRUE(s.step());
    return s.text(0);
}

// The lab's database: P1 completed and attentive; P2 completed, failed the catch trial;
// P3 quit after one rated trial (still `running`, before any catch trial); P4 paused
// after two; P5 aborted after one; P6 completed and then withdrew, its tombstone beside
// one of a session whose rows are already gone; D1 (twice) and D2 declined consent.
class AnalysisSessions : public ::testing::Test {
protected:
    void fill(const Protocol& p) {
        dir_ = lucent::test::scratch_dir(
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        path_ = (dir_ / "study.db").string();
        int64_t withdrawn_id = 0;
        {
            Store store(path_);
            lucent::test::run_full_session(store, p, "P1", 11);
            lucent::test::run_full_session(store, p, "P2", 12, /*catch_rating=*/2);
            partial_rated_ += run_partial_session(store, p, "P3", 13, 1, "running");
            partial_rated_ += run_partial_session(store, p, "P4", 14, 2, "paused");
            partial_rated_ += run_partial_session(store, p, "P5", 15, 1, "aborted");
            withdrawn_id = lucent::test::run_full_session(store, p, "P6", 16);
            // Two people declined consent, one of them on two pages: two codes.
            const int64_t study = store.ensure_study(p);
            store.decline_consent(study, "D1", "page-1");
            store.decline_consent(study, "D1", "page-2");
            store.decline_consent(study, "D2", "page-3");
        }
        const std::string withdrawn_uuid = uuid_of(path_, withdrawn_id);
        Database db(path_, SQLITE_OPEN_READWRITE);
        db.exec("INSERT INTO withdrawn_sessions (uuid, withdrawn_utc) VALUES ('" +
                withdrawn_uuid +
                "', '2026-01-02T10:00:00Z'), "
                "('00000000-0000-4000-8000-000000000000', '2026-01-01T10:00:00Z')");
    }
    fs::path dir_;
    std::string path_;
    int partial_rated_ = 0;  // rated trials answered by P3, P4 and P5
};

TEST_F(AnalysisSessions, OnlyCompletedSessionsAreAnalysedAndTheRestCountedByReason) {
    fill(lucent::test::small_protocol());
    ASSERT_EQ(partial_rated_, 4);
    const StudyObservations read = read_observations(path_);
    const SessionSelection& taken = read.selection;
    // P1 alone: 3 rated stimuli x 2 questions, one factor each.
    const auto rows = common::factor_ratings(read.table);
    ASSERT_EQ(rows.size(), 6u);
    for (const auto& r : rows) EXPECT_EQ(r.observation->participant, "P1");
    EXPECT_EQ(read.sessions, "completed");
    EXPECT_EQ(taken.total, 7);  // 6 present (P6 withdrawn) + 1 tombstone only
    EXPECT_EQ(taken.analysed, 1);
    EXPECT_EQ(taken.left_out.incomplete, 3);
    EXPECT_EQ(
        taken.left_out.incomplete_by_status,
        (std::map<std::string, int>{{"aborted", 1}, {"paused", 1}, {"running", 1}}));
    EXPECT_EQ(taken.left_out.failed_catch, 1);
    EXPECT_EQ(taken.left_out.withdrawn, 2);
    EXPECT_EQ(taken.analysed + taken.left_out.total(), taken.total);

    // export --format analysis says the same in its notes, and writes P1's rows only.
    const std::string csv = (dir_ / "ratings.csv").string();
    const ExportFileResult r = export_file(path_, "analysis", csv, false);
    EXPECT_EQ(r.rows, 6);
    ASSERT_EQ(r.notes.size(), 1u);
    EXPECT_EQ(r.notes[0],
              path_ +
                  ": 1 of 7 sessions analysed (completed sessions only, the analysis "
                  "plan's default); left out: 3 incomplete (1 aborted, 1 paused, "
                  "1 running), 1 failed catch trials, 2 withdrawn; 2 participant codes "
                  "declined consent");
    std::ifstream in(csv);
    std::set<std::string> participants;
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) participants.insert(line.substr(0, line.find(',')));
    EXPECT_EQ(participants, std::set<std::string>{"P1"});
}

TEST_F(AnalysisSessions, AllSessionsWhenAskedStillNeverTheWithdrawnOrFailedCatch) {
    fill(lucent::test::small_protocol());
    const StudyObservations read = read_observations(path_, {.sessions = "all"});
    const auto rows = common::factor_ratings(read.table);
    // P1's 3 rated trials and the 4 answered by P3, P4, P5; x 2 questions.
    EXPECT_EQ(rows.size(), static_cast<std::size_t>(2 * (3 + partial_rated_)));
    std::set<std::string> participants;
    for (const auto& r : rows) participants.insert(r.observation->participant);
    EXPECT_EQ(participants, (std::set<std::string>{"P1", "P3", "P4", "P5"}));
    EXPECT_EQ(read.selection.analysed, 4);
    EXPECT_EQ(read.selection.left_out.incomplete, 0);
    EXPECT_EQ(read.selection.left_out.failed_catch, 1);
    EXPECT_EQ(read.selection.left_out.withdrawn, 2);
    EXPECT_THROW(read_observations(path_, {.sessions = "some"}), StoreError);
}

TEST_F(AnalysisSessions, TheProtocolsAnalysisPlanCanTakeEverySession) {
    const std::string text =
        std::string(lucent::test::kSmallProtocol) + "\n[analysis]\nsessions = \"all\"\n";
    fill(parse_protocol(text, "all.toml"));
    const StudyObservations read = read_observations(path_);
    EXPECT_EQ(read.sessions, "all");
    EXPECT_EQ(read.selection.analysed, 4);
    EXPECT_NE(
        read.selection.note.find("sessions of every status, as the analysis plan says"),
        std::string::npos)
        << read.selection.note;
    // An explicit option wins over the plan.
    EXPECT_EQ(read_observations(path_, {.sessions = "completed"}).selection.analysed, 1);
}

TEST(AnalysisPlanSessions, AnUnknownValueIsRefusedNamingFileAndLine) {
    const std::string text = std::string(lucent::test::kSmallProtocol) +
                             "\n[analysis]\nsessions = \"finished\"\n";
    try {
        parse_protocol(text, "bad.toml");
        ADD_FAILURE() << "accepted";
    } catch (const ProtocolError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind("bad.toml:", 0), 0u) << message;
        EXPECT_NE(message.find("analysis.sessions"), std::string::npos) << message;
        EXPECT_NE(message.find("'finished'"), std::string::npos) << message;
    }
    EXPECT_EQ(lucent::test::small_protocol().analysis.sessions, "completed");
}

}  // namespace
}  // namespace lucent::study
