// The study store's guarantees, one suite over every backend (SQLite file, PostgreSQL
// server), as SQLite runs one suite over several VFS layers. The server is real
// (server_environment.h); every test gets a new database on it.
//
// Expected values come from the protocol and plan (trial counts, questions, the
// deterministic rating_for()), never from the store under test.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <pqxx/pqxx>
#include <set>
#include <thread>

#include "study/export.h"
#include "study/postgres/postgres_store.h"
#include "study/postgres/trial_journal.h"
#include "study/session/autopilot.h"
#include "study/session/session_flow.h"
#include "study/sqlite/sqlite_store.h"
#include "study/study_store.h"
#include "study/withdrawal.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::environment;
using lucent::test::provenance_for;

LocalPostgres& server() { return lucent::test::postgres_server(); }

// Two blocks, counterbalanced: participants alternate between 2 Latin-square cells.
std::string two_block_protocol_text() {
    std::string text = lucent::test::kSmallProtocol;
    const std::string main =
        "[[blocks]]\nid = \"main\"\nstimuli = [\"a\", \"b\", \"c\"]\n";
    text.replace(text.find(main), main.size(),
                 "[[blocks]]\nid = \"main\"\nstimuli = [\"a\", \"b\"]\n\n"
                 "[[blocks]]\nid = \"second\"\nstimuli = [\"c\", \"b\"]\n");
    return text;
}

// A fresh, empty store of the backend under test; the same one again with reopen().
class Backend : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::string slug;
        for (char c : test)
            slug +=
                std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
        dir_ = lucent::test::scratch_dir("backend_" + slug);
        if (GetParam() == "sqlite") {
            db_ = (dir_ / "study.db").string();
        } else {
            db_ = lucent::test::new_postgres_database(slug);
            init_study_store(db_);
        }
    }
    std::unique_ptr<StudyStore> open(const std::string& station = "station") {
        StoreOptions options;
        options.journal_path = (dir_ / (station + "-journal.db")).string();
        options.retry_interval_ms = 0;
        return open_study_store(db_, options);
    }
    bool is_server() const { return GetParam() == "postgresql"; }

    std::filesystem::path dir_;
    std::string db_;
};

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    return info.param;
}

TEST_P(Backend, WritesTheWholePlanWithTrialUuidsBeforeTheFirstTrial) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    int number = -1;
    const int64_t pid = store->ensure_participant(study, "P7", &number);
    EXPECT_EQ(number, 7);  // the code's digits
    const TrialPlan plan = plan_trials(p, 42, number);
    const SessionRow s = store->create_session(study, pid, plan, 42, {});
    const std::vector<TrialRow> trials = store->trials(s.id);
    ASSERT_EQ(trials.size(), plan.trials.size());
    std::set<std::string> uuids;
    for (size_t i = 0; i < trials.size(); ++i) {
        EXPECT_EQ(trials[i].stimulus, plan.trials[i].stimulus);
        EXPECT_EQ(trials[i].is_catch, plan.trials[i].is_catch);
        EXPECT_FALSE(trials[i].answered);
        ASSERT_EQ(trials[i].uuid.size(), 36u);
        EXPECT_EQ(trials[i].uuid[14], '4');
        uuids.insert(trials[i].uuid);
    }
    EXPECT_EQ(uuids.size(), trials.size());
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM stimulus_parameters sp JOIN stimuli s ON "
                         "s.id = sp.stimulus_id WHERE s.stimulus_key = 'b' AND "
                         "sp.name = 'thickness_exponent' AND sp.value = '25'"),
        1);
}

TEST_P(Backend, RecordsEachTrialOnceAndRefusesDuplicatesAndBadRatings) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    const int64_t pid = store->ensure_participant(study, "anna", nullptr);
    const SessionRow s = store->create_session(study, pid, plan_trials(p, 1, 1), 1, {});
    const std::vector<TrialRow> trials = store->trials(s.id);
    store->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
    EXPECT_THROW(
        store->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0])),
        StoreError);
    TrialOutcome bad = lucent::test::outcome_for(p, trials[1]);
    bad.responses[1].rating = 8;
    EXPECT_THROW(store->record_trial(s.id, trials[1].id, bad), StoreError);
    bad.responses[1].rating = 0;
    EXPECT_THROW(store->record_trial(s.id, trials[1].id, bad), StoreError);
    TrialOutcome missing = lucent::test::outcome_for(p, trials[1]);
    missing.responses.pop_back();
    EXPECT_THROW(store->record_trial(s.id, trials[1].id, missing), StoreError);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              2);  // 1 trial x 2 questions
    EXPECT_EQ(store->pending_trials(), 0);
    // A fresh connection sees the same: committed, not cached.
    auto again = open("second");
    const std::vector<TrialRow> seen = again->trials(s.id);
    EXPECT_TRUE(seen[0].answered);
    EXPECT_FALSE(seen[1].answered);
}

// Issue 27 item 6: the rules are written once above the backends (study/store_rules.h),
// so every backend refuses the same answers with the same line.
TEST_P(Backend, EveryBackendRefusesWithTheSameLines) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    const int64_t pid = store->ensure_participant(study, "anna", nullptr);
    const SessionRow s = store->create_session(study, pid, plan_trials(p, 1, 1), 1, {});
    const std::vector<TrialRow> trials = store->trials(s.id);
    const auto refusal = [&](const std::function<void()>& call) {
        try {
            call();
        } catch (const StoreError& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    const std::string trial0 = store->name() + ": trial " + std::to_string(trials[0].id);
    TrialOutcome same_question_twice = lucent::test::outcome_for(p, trials[0]);
    same_question_twice.responses[1].question = same_question_twice.responses[0].question;
    EXPECT_EQ(
        refusal([&] { store->record_trial(s.id, trials[0].id, same_question_twice); }),
        trial0 + " rates question '" + same_question_twice.responses[0].question +
            "' twice");
    const int64_t other_pid = store->ensure_participant(study, "ben", nullptr);
    const SessionRow other =
        store->create_session(study, other_pid, plan_trials(p, 2, 2), 2, {});
    EXPECT_EQ(refusal([&] {
                  store->record_trial(other.id, trials[0].id,
                                      lucent::test::outcome_for(p, trials[0]));
              }),
              trial0 + " is not part of session " + std::to_string(other.id));
    store->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
    EXPECT_EQ(refusal([&] {
                  store->record_trial(s.id, trials[0].id,
                                      lucent::test::outcome_for(p, trials[0]));
              }),
              trial0 + " already has ratings; refusing to record it twice");
    for (const TrialRow& t : store->trials(s.id))
        if (!t.answered) store->record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
    EXPECT_EQ(refusal([&] { store->set_status(s.id, "paused", false); }),
              store->name() + ": session " + s.uuid +
                  " is completed; refusing to set it paused");
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              static_cast<int64_t>(trials.size() * p.questions.size()));
}

TEST_P(Backend, ResumeFindsTheUnfinishedSessionAndTheLastTrialCompletesIt) {
    const Protocol p = lucent::test::small_protocol();
    int64_t session_id = 0;
    size_t planned = 0;
    {
        auto store = open();
        const int64_t study = store->ensure_study(p);
        int number = 0;
        const int64_t pid = store->ensure_participant(study, "P3", &number);
        const SessionRow s =
            store->create_session(study, pid, plan_trials(p, 9, number), 9, {});
        session_id = s.id;
        const std::vector<TrialRow> trials = store->trials(s.id);
        planned = trials.size();
        for (size_t i = 0; i < 2; ++i)
            EXPECT_FALSE(store->record_trial(s.id, trials[i].id,
                                             lucent::test::outcome_for(p, trials[i])));
        store->set_status(s.id, "paused", false);
    }
    auto store = open();
    const std::optional<SessionRow> resumed = store->unfinished_session("P3");
    ASSERT_TRUE(resumed);
    EXPECT_EQ(resumed->id, session_id);
    EXPECT_EQ(resumed->seed, 9u);
    EXPECT_FALSE(store->has_completed_session("P3"));
    EXPECT_EQ(store->begin_segment(session_id, {}), 2);
    const std::vector<TrialRow> trials = store->trials(session_id);
    ASSERT_EQ(trials.size(), planned);
    bool completed = false;
    for (const TrialRow& t : trials) {
        if (t.answered) continue;
        EXPECT_FALSE(completed) << "completed before the last trial";
        completed =
            store->record_trial(session_id, t.id, lucent::test::outcome_for(p, t));
    }
    EXPECT_TRUE(completed);
    EXPECT_TRUE(store->has_completed_session("P3"));
    EXPECT_FALSE(store->unfinished_session("P3"));
    EXPECT_THROW(store->set_status(session_id, "paused", false), StoreError);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              static_cast<int64_t>(planned * p.questions.size()));
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE status = 'completed' AND "
                         "ended_utc IS NOT NULL"),
        1);
}

TEST_P(Backend, WithdrawalDeletesEverythingAndRetiresTheNumber) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    int first = 0, second = 0, third = 0;
    store->ensure_participant(study, "anna", &first);
    const int64_t bob = store->ensure_participant(study, "bob", &second);
    EXPECT_EQ(first, 1);
    EXPECT_EQ(second, 2);
    const SessionRow s =
        store->create_session(study, bob, plan_trials(p, 2, second), 2, {});
    const TrialRow t = store->trials(s.id)[0];
    store->record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
    ASSERT_TRUE(store->participant_counts("bob"));
    EXPECT_EQ(store->participant_counts("bob")->ratings, 2);
    EXPECT_TRUE(store->withdraw_participant("bob"));
    EXPECT_FALSE(store->withdraw_participant("bob"));
    EXPECT_FALSE(store->participant_counts("bob"));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"), 0);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials"), 0);
    store->ensure_participant(study, "carl", &third);
    EXPECT_EQ(third, 3);  // 2 is retired, never handed out again
}

TEST_P(Backend, ALabDeclineBeforeConsentKeepsOnlyTheCodesSaltedHash) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    int number = 0;
    const int64_t dora = store->ensure_participant(study, "dora", &number);
    SessionEnvironment env;
    env.machine_id = "lab-station-7";
    env.gl_renderer = "a renderer string";
    const SessionRow s =
        store->create_session(study, dora, plan_trials(p, number, number), 3, env);
    EXPECT_TRUE(store->forget_declined_session(s.id));
    for (const char* table : {"participants", "sessions", "session_segments", "trials"})
        EXPECT_EQ(store->query_int(std::string("SELECT count(*) FROM ") + table), 0)
            << table;
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes WHERE code_hash = "
                               "'dora' OR salt = 'dora' OR page_uuid IS NOT NULL"),
              0);
    // dora declines again later: the same code, still one.
    const int64_t again = store->ensure_participant(study, "dora", &number);
    const SessionRow s2 =
        store->create_session(study, again, plan_trials(p, number, number), 5, env);
    EXPECT_TRUE(store->forget_declined_session(s2.id));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), 1);

    // A session with consent and an answer is not forgotten (it is aborted instead).
    const int64_t emil = store->ensure_participant(study, "emil", &number);
    const SessionRow e =
        store->create_session(study, emil, plan_trials(p, number, number), 4, env);
    store->set_consent(e.id);
    const TrialRow t = store->trials(e.id)[0];
    store->record_trial(e.id, t.id, lucent::test::outcome_for(p, t));
    EXPECT_FALSE(store->forget_declined_session(e.id));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              static_cast<int64_t>(p.questions.size()));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM consent_declines"), 0);
}

// Issue 44 item 5: declines count participant codes, not pages. One code declining on
// many pages (a script reloading, a person coming back) is one row, its newest page the
// declined one; stations declining one code at once count it once; fresh codes stop
// adding rows at kMaxDeclinedCodes.
TEST_P(Backend, DeclinesCountEachCodeOnceAndStopAddingRowsAtTheCap) {
    auto store = open();
    const int64_t study = store->ensure_study(lucent::test::small_protocol());
    EXPECT_TRUE(store->decline_consent(study, "P1", "page-1"));
    for (int i = 2; i <= 40; ++i)
        EXPECT_FALSE(store->decline_consent(study, "P1", "page-" + std::to_string(i)));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), 1);
    EXPECT_TRUE(store->consent_declined("page-40"));
    EXPECT_FALSE(store->consent_declined("page-1"));  // superseded by the code's newest
    EXPECT_FALSE(store->consent_declined("page-never"));
    // Nothing of the code itself is kept.
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes WHERE code_hash LIKE "
                               "'%P1%' OR salt LIKE '%P1%'"),
              0);

    // Eight connections declining one new code at once: counted once.
    std::vector<std::thread> threads;
    std::atomic<int> counted{0};
    std::vector<std::string> errors(8);
    for (int k = 0; k < 8; ++k)
        threads.emplace_back([&, k] {
            try {
                auto other = open("decline" + std::to_string(k));
                if (other->decline_consent(study, "TWICE", "t-" + std::to_string(k)))
                    ++counted;
            } catch (const std::exception& e) {
                errors[k] = e.what();
            }
        });
    for (std::thread& t : threads) t.join();
    for (const std::string& e : errors) EXPECT_EQ(e, "");
    EXPECT_EQ(counted.load(), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), 2);

    // Fresh codes (a script): the rows stop at the cap; a code already held still
    // updates its page.
    for (int i = 2; i < kMaxDeclinedCodes; ++i)
        store->decline_consent(study, "F" + std::to_string(i), "");
    ASSERT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), kMaxDeclinedCodes);
    EXPECT_FALSE(store->decline_consent(study, "ONE-TOO-MANY", "over"));
    EXPECT_FALSE(store->consent_declined("over"));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM declined_codes"), kMaxDeclinedCodes);
    EXPECT_FALSE(store->decline_consent(study, "P1", "page-41"));
    EXPECT_TRUE(store->consent_declined("page-41"));
}

// Issue 44 item 6: consent is written in the enrolment's transaction: a session enrolled
// on consent has it without a second call, and an enrolment that fails leaves neither.
TEST_P(Backend, AnOnlineEnrolmentOnConsentStoresTheConsentInItsOwnTransaction) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    OnlineEnrolment how;
    how.seed = 7;
    how.active_since_utc = "2000-01-01T00:00:00.000Z";
    how.plan = [&](int cell) { return plan_trials(p, how.seed, cell); };
    how.consented = true;
    const OnlineSession yes = store->enrol_online(study, "C1", how, {});
    EXPECT_TRUE(store->has_consent(yes.session.id));
    how.consented = false;  // a protocol without a consent screen
    const OnlineSession none = store->enrol_online(study, "C2", how, {});
    EXPECT_FALSE(store->has_consent(none.session.id));
    // A fault inside the enrolment: nothing of it, consent included.
    how.consented = true;
    how.plan = [&](int) -> TrialPlan { throw StoreUnavailable("fault injected"); };
    EXPECT_THROW(store->enrol_online(study, "C3", how, {}), StoreUnavailable);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM sessions"), 2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM participants WHERE code = 'C3'"), 0);
}

TEST_P(Backend, AParticipantRunningOnOneStationIsRefusedOnAnother) {
    auto a = open("a");
    auto b = open("b");
    a->claim_participant("P5");
    try {
        b->claim_participant("P5");
        FAIL() << "second station was allowed to run P5";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("'P5'"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;  // one line
    }
    b->claim_participant("P6");  // others are free
    a.reset();                   // station A ends: P5 may be resumed elsewhere
    // A server ends a closed connection's backend (and its locks) a moment after the
    // close; a station starting then is refused, so ask again for up to 5 s.
    bool claimed = false;
    for (int attempt = 0; attempt < 100 && !claimed; ++attempt) {
        try {
            b->claim_participant("P5");
            claimed = true;
        } catch (const StoreError&) {
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        }
    }
    EXPECT_TRUE(claimed);
}

TEST_P(Backend, RacingStationsNeverShareAParticipantNumber) {
    const Protocol p = lucent::test::small_protocol();
    open()->ensure_study(p);
    constexpr int kStations = 8, kEach = 5;
    std::vector<std::vector<int>> numbers(kStations);
    std::vector<std::thread> threads;
    for (int k = 0; k < kStations; ++k)
        threads.emplace_back([&, k] {
            auto store = open("s" + std::to_string(k));
            const int64_t study = store->ensure_study(p);
            for (int i = 0; i < kEach; ++i) {
                int n = 0;
                // No trailing digits: the number is allocated by the store.
                store->ensure_participant(study,
                                          "st" + std::string(1, char('a' + k)) + "-" +
                                              std::string(1, char('a' + i)),
                                          &n);
                numbers[k].push_back(n);
            }
        });
    for (std::thread& t : threads) t.join();
    std::set<int> all;
    for (const auto& v : numbers) all.insert(v.begin(), v.end());
    EXPECT_EQ(all.size(), size_t(kStations * kEach));
    EXPECT_EQ(*all.begin(), 1);
    EXPECT_EQ(*all.rbegin(), kStations * kEach);
}

TEST_P(Backend, RefusesASecondProtocolInOneStudyStore) {
    auto store = open();
    store->ensure_study(lucent::test::small_protocol());
    EXPECT_THROW(store->ensure_study(builtin_protocol("thesis")), StoreError);
    EXPECT_EQ(store->ensure_study(lucent::test::small_protocol()),
              store->ensure_study(lucent::test::small_protocol()));
}

TEST_P(Backend, EachRatingIsCheckedAgainstItsOwnQuestionsScale) {
    auto store = open();
    const Protocol p = lucent::test::mixed_scale_protocol();  // 7 points, then 5
    const int64_t study = store->ensure_study(p);
    const int64_t pid = store->ensure_participant(study, "P1", nullptr);
    const SessionRow s = store->create_session(study, pid, plan_trials(p, 3, 1), 3, {});
    const std::vector<TrialRow> trials = store->trials(s.id);
    auto outcome = [&](int translucent, int realistic) {
        TrialOutcome o;
        o.onset_ns = 1;
        o.confirm_ns = 2;
        o.responses = {{"translucent", translucent, 500, 0, 1, 2},
                       {"realistic", realistic, 500, 0, 1, 2}};
        return o;
    };
    store->record_trial(s.id, trials[0].id, outcome(7, 5));
    try {
        store->record_trial(s.id, trials[1].id, outcome(4, 6));
        ADD_FAILURE() << "a 6 on a 5-point scale was stored";
    } catch (const StoreError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("'realistic'"), std::string::npos) << message;
        EXPECT_NE(message.find("1..5"), std::string::npos) << message;
    }
    TrialOutcome unknown = outcome(3, 3);
    unknown.responses[1].question = "varnished";
    EXPECT_THROW(store->record_trial(s.id, trials[1].id, unknown), StoreError);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"), 2);
    EXPECT_EQ(store->pending_trials(), 0);  // refused trials leave no journal entry
    store->record_trial(s.id, trials[1].id, outcome(1, 1));
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"), 4);
}

// Issue 44 item 6: the pictures served beyond the study's stimuli (series steps,
// staircase ladders) have provenance rows: each picture's file and content hash, once per
// distinct set of files, and each segment names its set.
TEST_P(Backend, SeriesPicturesAreRecordedOncePerSetAndEachSegmentNamesItsSet) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    auto picture = [](const std::string& id, const std::string& hash) {
        StimulusProvenance s;
        s.stimulus = id;
        s.source = "images";
        s.file = id + ".png";
        s.content_hash = hash;
        s.software_version = "lucent test";
        s.build_hash = "b1";
        return s;
    };
    SessionEnvironment env = environment("web", "agent", 60);
    env.series_pictures = {picture("a@k=0.1", "h1"), picture("a@k=0.2", "h2"),
                           picture("a@k=0.3", "h3")};
    auto enrol = [&](const std::string& code) {
        int number = 0;
        const int64_t pid = store->ensure_participant(study, code, &number);
        return store->create_session(study, pid, plan_trials(p, 5, number), 5, env);
    };
    enrol("P1");
    enrol("P2");
    EXPECT_EQ(store->query_int("SELECT count(*) FROM series_pictures"), 3);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM series_pictures WHERE picture = "
                               "'a@k=0.2' AND file = 'a@k=0.2.png' AND content_hash = "
                               "'h2' AND software_version = 'lucent test'"),
              1);
    EXPECT_EQ(store->query_int("SELECT count(DISTINCT series_set) FROM session_segments"),
              1);
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM session_segments g WHERE "
                         "(SELECT count(*) FROM series_pictures x WHERE x.set_hash = "
                         "g.series_set) = 3"),
        2);
    // One picture re-rendered (another folder, another instance): a second set.
    env.series_pictures[1].content_hash = "h2-new";
    enrol("P3");
    EXPECT_EQ(store->query_int("SELECT count(*) FROM series_pictures"), 6);
    EXPECT_EQ(store->query_int("SELECT count(DISTINCT series_set) FROM session_segments"),
              2);
    // A lab segment that showed no series names none.
    env.series_pictures.clear();
    enrol("P4");
    EXPECT_EQ(store->query_int(
                  "SELECT count(*) FROM session_segments WHERE series_set IS NULL"),
              1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM series_pictures"), 6);
}

TEST_P(Backend, AResumeAddsASegmentAndLaterSessionsMustShowTheSameValues) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    int number = 0;
    const int64_t pid = store->ensure_participant(study, "P1", &number);
    SessionEnvironment first = environment("lab-a", "GPU A", 60);
    first.stimuli = provenance_for(p, "0.8,0.55,0.35");
    const SessionRow s =
        store->create_session(study, pid, plan_trials(p, 5, number), 5, first);
    const std::vector<TrialRow> trials = store->trials(s.id);
    store->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
    SessionEnvironment second = environment("lab-b", "GPU B", 144);
    second.stimuli = first.stimuli;
    EXPECT_EQ(store->begin_segment(s.id, second), 2);
    second.measured_refresh_hz = 143.9;
    store->update_environment(s.id, second);
    store->record_trial(s.id, trials[1].id, lucent::test::outcome_for(p, trials[1]));
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM session_segments WHERE segment = 1 AND "
                         "machine_id = 'lab-a' AND gl_renderer = 'GPU A' AND "
                         "display_refresh_hz = 60 AND measured_refresh_hz IS NULL AND "
                         "stimulus_source = 'live'"),
        1);
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM session_segments WHERE segment = 2 AND "
                         "machine_id = 'lab-b' AND measured_refresh_hz = 143.9"),
        1);
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE gl_renderer = 'GPU A' AND "
                         "display_refresh_hz = 60"),
        1);
    // Each trial knows the segment it was answered in.
    EXPECT_EQ(store->query_int(
                  "SELECT count(*) FROM trials t JOIN session_segments g ON "
                  "g.id = t.segment_id WHERE (t.position = 0 AND g.segment = 1) OR "
                  "(t.position = 1 AND g.segment = 2)"),
              2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM segment_stimuli"),
              2 * static_cast<int64_t>(p.stimuli.size()));
    // Values are recorded once per stimulus (albedo, fov_y and its own parameters), not
    // again by the second segment.
    int64_t values = 0;
    for (const Stimulus& spec : p.stimuli)
        values += 2 + static_cast<int64_t>(spec.parameters.size());
    EXPECT_EQ(store->query_int("SELECT count(*) FROM stimulus_values"), values);
    try {
        store->check_stimulus_values(provenance_for(p, "0.7,0.55,0.35"));
        FAIL() << "different resolved values accepted";
    } catch (const StoreError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("stimulus 'a'"), std::string::npos) << what;
        EXPECT_NE(what.find("'albedo'"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    EXPECT_NO_THROW(store->check_stimulus_values(provenance_for(p, "0.8,0.55,0.35")));
}

// ---- stations driven by the simulated participant -------------------------------------

struct StationResult {
    std::string error;
    int cell = -1;
    std::map<std::string, int> ratings;  // "trial uuid/question" -> rating, as answered
};

// One lab station: opens the store, claims and enrols `code`, plans and stores a session,
// then lets a seeded autopilot answer every screen on a simulated clock (16 ms frames).
// `after_trial` runs after each answered trial (tests stop the server there).
StationResult run_station(const std::function<std::unique_ptr<StudyStore>()>& open_store,
                          const Protocol& p, const std::string& code, uint64_t seed,
                          const std::function<void(int)>& after_trial = {}) {
    StationResult out;
    try {
        auto store = open_store();
        const int64_t study = store->ensure_study(p);
        store->claim_participant(code);
        int number = 0;
        const int64_t pid = store->ensure_participant(study, code, &number);
        const SessionRow s =
            store->create_session(study, pid, plan_trials(p, seed, number), seed, {});
        out.cell = s.cell;
        const std::vector<TrialRow> trials = store->trials(s.id);
        int64_t now = 1'000'000'000;
        SessionFlow flow(p, *store, s.id, trials, false, now);
        Autopilot pilot = Autopilot::from_seed(seed, 40.0);
        size_t answered = 0;
        if (after_trial) after_trial(0);  // the session is on screen
        for (int frame = 0; frame < 200000 && !flow.finished(); ++frame) {
            now += 16'000'000;
            flow.tick(now);
            flow.presented(flow.serial(), now);
            for (const std::string& name : pilot.due(now, flow.view()))
                flow.key(autopilot_key(name, now));
            if (flow.answered_trials() != answered) {
                answered = flow.answered_trials();
                if (after_trial) after_trial(static_cast<int>(answered));
            }
        }
        if (!flow.finished()) throw StoreError("station " + code + " did not finish");
        for (int attempt = 0; attempt < 200 && store->pending_trials() > 0; ++attempt) {
            try {
                store->sync();
            } catch (const StoreError&) {
                std::this_thread::sleep_for(std::chrono::milliseconds(50));
            }
        }
        if (store->pending_trials() != 0) throw StoreError(code + ": journal not empty");
    } catch (const std::exception& e) {
        out.error = e.what();
    }
    return out;
}

// Every planned trial of every session has exactly one rating per question, and the
// number of responses is exactly trials x questions: nothing lost, nothing twice.
void expect_every_rating_once(StudyStore& store, const Protocol& p, int sessions) {
    const int64_t trials = store.query_int("SELECT count(*) FROM trials");
    const int64_t per_session = static_cast<int64_t>(plan_trials(p, 1, 1).trials.size());
    EXPECT_EQ(trials, sessions * per_session);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM responses"),
              trials * static_cast<int64_t>(p.questions.size()));
    EXPECT_EQ(
        store.query_int("SELECT count(*) FROM (SELECT DISTINCT trial_id, question FROM "
                        "responses) d"),
        trials * static_cast<int64_t>(p.questions.size()));
    EXPECT_EQ(
        store.query_int("SELECT count(*) FROM trials t WHERE NOT EXISTS (SELECT 1 FROM "
                        "responses r WHERE r.trial_id = t.id)"),
        0);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              sessions);
}

TEST_P(Backend, EightStationsAtOnceLoseNothingAndBalanceTheCells) {
    const Protocol p = parse_protocol(two_block_protocol_text(), "two_blocks.toml");
    open()->ensure_study(p);
    constexpr int kStations = 8;
    std::vector<StationResult> results(kStations);
    std::vector<std::thread> threads;
    for (int k = 0; k < kStations; ++k)
        threads.emplace_back([&, k] {
            results[k] = run_station([&] { return open("station" + std::to_string(k)); },
                                     p, "lab-" + std::string(1, char('a' + k)), 100 + k);
        });
    for (std::thread& t : threads) t.join();
    std::map<int, int> per_cell;
    for (const StationResult& r : results) {
        EXPECT_EQ(r.error, "");
        ++per_cell[r.cell];
    }
    // 2 blocks: a 2-row Latin square; 8 consecutive numbers fill each row 4 times.
    EXPECT_EQ(per_cell, (std::map<int, int>{{0, 4}, {1, 4}}));
    auto store = open();
    expect_every_rating_once(*store, p, kStations);
    EXPECT_EQ(store->query_int("SELECT count(DISTINCT number) FROM participants"),
              kStations);
}

// Issue 26 item 7: a claim ends when released, so another station may run the code; on
// PostgreSQL the connection holds no advisory lock afterwards.
TEST_P(Backend, AReleasedClaimCanBeTakenByAnotherStationAtOnce) {
    auto serve = open("serve");
    auto lab = open("lab");
    for (int i = 0; i < 20; ++i) serve->claim_participant("web" + std::to_string(i));
    EXPECT_THROW(lab->claim_participant("web3"), StoreError);
    for (int i = 0; i < 20; ++i) serve->release_participant("web" + std::to_string(i));
    serve->release_participant("never-claimed");  // a no-op
    if (is_server())
        EXPECT_EQ(
            serve->query_int("SELECT count(*) FROM pg_locks WHERE locktype = 'advisory' "
                             "AND pid = pg_backend_pid()"),
            0);
    EXPECT_NO_THROW(lab->claim_participant("web3"));
    // Now the lab holds it: the serve store is refused, and may claim again once
    // released.
    EXPECT_THROW(serve->claim_participant("web3"), StoreError);
    lab->release_participant("web3");
    EXPECT_NO_THROW(serve->claim_participant("web3"));
}

std::string four_block_protocol_text() {
    std::string text = lucent::test::kSmallProtocol;
    const std::string main =
        "[[blocks]]\nid = \"main\"\nstimuli = [\"a\", \"b\", \"c\"]\n";
    text.replace(text.find(main), main.size(),
                 "[[blocks]]\nid = \"main\"\nstimuli = [\"a\"]\n\n"
                 "[[blocks]]\nid = \"second\"\nstimuli = [\"b\"]\n\n"
                 "[[blocks]]\nid = \"third\"\nstimuli = [\"c\"]\n\n"
                 "[[blocks]]\nid = \"fourth\"\nstimuli = [\"b\", \"c\"]\n");
    return text;
}

// Issue 26 item 8: serve processes and lab stations enrolling at once on one store never
// share a number, and the online arrivals fill the cells evenly (counted under the lock
// that hands out numbers).
TEST_P(Backend, OnlineEnrolmentsFromManyConnectionsAtOnceStayUniqueAndBalanced) {
    const Protocol p = parse_protocol(four_block_protocol_text(), "four_blocks.toml");
    ASSERT_EQ(latin_square_rows(4), 4);
    open()->ensure_study(p);
    constexpr int kServers = 8, kEach = 2;
    std::vector<std::string> errors(kServers);
    std::vector<std::thread> threads;
    for (int k = 0; k < kServers; ++k)
        threads.emplace_back([&, k] {
            try {
                auto store = open("serve" + std::to_string(k));
                const int64_t study = store->ensure_study(p);
                for (int i = 0; i < kEach; ++i) {
                    OnlineEnrolment how;
                    how.seed = static_cast<uint64_t>(k * 10 + i);
                    how.cells = 4;
                    how.active_since_utc = "2000-01-01T00:00:00.000Z";
                    how.plan = [&](int cell) { return plan_trials(p, how.seed, cell); };
                    // Codes whose digits would all pick one cell, and digitless ones.
                    const std::string code = i == 0
                                                 ? "P0" + std::to_string(k * 4)
                                                 : "web-" + std::string(1, char('a' + k));
                    store->enrol_online(study, code, how, {});
                }
                // A lab station among them keeps the code's digits.
                if (k == 0) {
                    int n = 0;
                    store->ensure_participant(study, "LAB90", &n);
                    if (n != 90) errors[k] = "lab number " + std::to_string(n);
                }
            } catch (const std::exception& e) {
                errors[k] = e.what();
            }
        });
    for (std::thread& t : threads) t.join();
    for (const std::string& e : errors) EXPECT_EQ(e, "");
    auto store = open();
    EXPECT_EQ(store->query_int("SELECT count(*) FROM sessions"), kServers * kEach);
    EXPECT_EQ(store->query_int("SELECT count(DISTINCT number) FROM participants"),
              kServers * kEach + 1);
    // The online numbers: 1..16 (the lab's 90 may come before some: then 91..).
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM participants WHERE code <> 'LAB90' AND "
                         "(number BETWEEN 1 AND 16 OR number BETWEEN 91 AND 106)"),
        kServers * kEach);
    for (int cell = 0; cell < 4; ++cell)
        EXPECT_EQ(store->query_int("SELECT count(*) FROM sessions WHERE cell = " +
                                   std::to_string(cell)),
                  kServers * kEach / 4)
            << "cell " << cell;
    EXPECT_EQ(store->query_int(
                  "SELECT count(*) FROM sessions WHERE allocation LIKE "
                  "'online arrival %: cell % of 4, the fewest completed + active %'"),
              kServers * kEach);
    // Each session's plan is its cell's Latin-square row.
    EXPECT_EQ(store->query_int(
                  "SELECT count(*) FROM sessions WHERE block_order NOT LIKE '%,%,%,%'"),
              0);
}

// Issue 26 item 10: a reload replaces a segment nothing was answered in.
TEST_P(Backend, AResumeSegmentReplacesASegmentWithoutAnswersAndAddsOneAfterAnAnswer) {
    auto store = open();
    const Protocol p = lucent::test::small_protocol();
    const int64_t study = store->ensure_study(p);
    int number = 0;
    const int64_t pid = store->ensure_participant(study, "P1", &number);
    SessionEnvironment env;
    env.machine_id = "first";
    const SessionRow s =
        store->create_session(study, pid, plan_trials(p, 1, number), 1, env);
    for (int i = 0; i < 10; ++i) {
        env.machine_id = "reload" + std::to_string(i);
        EXPECT_EQ(store->resume_segment(s.id, env), 1);
    }
    EXPECT_EQ(store->query_int("SELECT count(*) FROM session_segments"), 1);
    // The replaced first segment's environment is the session row's too.
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE machine_id = 'reload9'"),
        1);
    const std::vector<TrialRow> trials = store->trials(s.id);
    store->record_trial(s.id, trials[0].id, lucent::test::outcome_for(p, trials[0]));
    EXPECT_EQ(store->resume_segment(s.id, env), 2);
    EXPECT_EQ(store->resume_segment(s.id, env), 2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM session_segments"), 2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM trials t JOIN session_segments g ON "
                               "g.id = t.segment_id AND g.segment = 1"),
              1);
}

INSTANTIATE_TEST_SUITE_P(Stores, Backend, ::testing::Values("sqlite", "postgresql"),
                         param_name);

// ---- the server alone: schema, URI, outages -------------------------------------------

class Server : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = lucent::test::scratch_dir("server_" + test);
        uri_ = lucent::test::new_postgres_database(test);
    }
    void TearDown() override {
        if (!server().running()) server().start();
    }
    StoreOptions options(const std::string& station) {
        StoreOptions o;
        o.journal_path = (dir_ / (station + "-journal.db")).string();
        o.retry_interval_ms = 0;
        return o;
    }
    std::filesystem::path dir_;
    std::string uri_;
};

TEST_F(Server, SchemaIsTheSqliteSchemaTableForTableAndColumnForColumn) {
    init_study_store(uri_);
    const auto sqlite_path = (dir_ / "model.db").string();
    Store model(sqlite_path);
    auto server = open_study_store(uri_, options("x"));
    int tables = 0;
    Statement t = model.db().prepare(
        "SELECT name FROM sqlite_schema WHERE type = 'table' AND name NOT LIKE "
        "'sqlite_%'");
    while (t.step()) {
        ++tables;
        Statement c = model.db().prepare("SELECT name FROM pragma_table_info(?)");
        c.bind(1, t.text(0));
        while (c.step()) {
            // Names are the model's (this build's constants): a column missing on the
            // server counts 0.
            EXPECT_EQ(
                server->query_int("SELECT count(*) FROM information_schema.columns WHERE "
                                  "table_schema = 'public' AND table_name = '" +
                                  t.text(0) + "' AND column_name = '" + c.text(0) + "'"),
                1)
                << t.text(0) << "." << c.text(0);
        }
    }
    // Schema 5 added withdrawn_sessions, withdrawn_codes and consent_declines to the 11,
    // schema 7 adjustments, schema 8 declined_pages, schema 9 declined_codes and
    // series_pictures.
    EXPECT_EQ(tables, 18);
    // The server has the same tables plus lucent_schema, nothing else.
    EXPECT_EQ(server->query_int("SELECT count(*) FROM information_schema.tables WHERE "
                                "table_schema = 'public'"),
              tables + 1);
}

TEST_F(Server, UninitialisedOlderAndNewerSchemasAreRefusedWithOneLine) {
    auto message = [&] {
        try {
            open_study_store(uri_, options("x"));
        } catch (const StoreError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(message().find("lucent store init"), std::string::npos);
    EXPECT_EQ(init_study_store(uri_), std::make_pair(0, kSchemaVersion));
    EXPECT_EQ(init_study_store(uri_), std::make_pair(kSchemaVersion, kSchemaVersion));
    EXPECT_EQ(message(), "");
    {
        pqxx::connection c(uri_);
        pqxx::work w(c);
        w.exec_params("UPDATE lucent_schema SET version = $1", kSchemaVersion + 1);
        w.commit();
    }
    const std::string newer = message();
    EXPECT_NE(newer.find("newer Lucent (schema " + std::to_string(kSchemaVersion + 1)),
              std::string::npos)
        << newer;
    EXPECT_EQ(newer.find('\n'), std::string::npos);
    EXPECT_THROW(init_study_store(uri_), StoreError);  // never downgraded
}

TEST_F(Server, PasswordsAndUnknownSchemesAreRefusedBeforeConnecting) {
    EXPECT_THROW(open_study_store("postgresql://anna:secret@localhost/study"),
                 StoreError);
    EXPECT_THROW(open_study_store("postgresql://anna@localhost/study?password=secret"),
                 StoreError);
    try {
        open_study_store("mysql://anna@localhost/study");
        FAIL();
    } catch (const StoreError& e) {
        EXPECT_NE(std::string(e.what()).find("postgresql://"), std::string::npos);
    }
}

TEST_F(Server, AResendOfAConfirmedTrialIsRecognisedNotStoredTwice) {
    init_study_store(uri_);
    const Protocol p = lucent::test::small_protocol();
    auto store = open_study_store(uri_, options("a"));
    const int64_t study = store->ensure_study(p);
    const int64_t pid = store->ensure_participant(study, "P1", nullptr);
    const SessionRow s = store->create_session(study, pid, plan_trials(p, 4, 1), 4, {});
    const TrialRow t = store->trials(s.id)[0];
    const TrialOutcome o = lucent::test::outcome_for(p, t);
    store->record_trial(s.id, t.id, o);
    // The server committed, but say the reply was lost: the journal still holds it.
    TrialJournal journal(options("a").journal_path, uri_);
    journal.add({t.uuid, s.uuid, utc_now_iso8601(), o});
    EXPECT_EQ(store->pending_trials(), 1);
    EXPECT_EQ(store->sync(), 1);
    EXPECT_EQ(store->pending_trials(), 0);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"), 2);
    // Other ratings under the same UUID are a conflict: refused, kept, nothing changed.
    TrialOutcome other = o;
    other.responses[0].rating = o.responses[0].rating % 7 + 1;
    journal.add({t.uuid, s.uuid, utc_now_iso8601(), other});
    EXPECT_THROW(store->sync(), StoreError);
    EXPECT_EQ(store->pending_trials(), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"), 2);
}

TEST_F(Server, StoppedMidSessionEveryCommittedRatingArrivesOnce) {
    init_study_store(uri_);
    const Protocol p = parse_protocol(two_block_protocol_text(), "two_blocks.toml");
    open_study_store(uri_, options("setup"))->ensure_study(p);
    const int per_session = static_cast<int>(plan_trials(p, 1, 1).trials.size());
    ASSERT_GE(per_session, 6);
    constexpr int kStations = 4;
    // Station 0 stops the server after its 2nd trial, once every station's session is on
    // screen, and starts it again after its 4th; stations take 30 ms per trial, so the
    // others record trials while the server is down (journaled; their sessions run on).
    std::atomic<int> journaled_during_outage{0}, started{0};
    std::vector<StationResult> results(kStations);
    std::vector<std::thread> threads;
    for (int k = 0; k < kStations; ++k)
        threads.emplace_back([&, k] {
            auto after = [&, k](int answered) {
                if (answered == 0) {
                    ++started;
                    return;
                }
                if (k == 0 && answered == 2) {
                    while (started.load() < kStations)
                        std::this_thread::sleep_for(std::chrono::milliseconds(5));
                    server().stop();
                }
                if (k == 0 && answered == 4) server().start();
                if (!server().running()) ++journaled_during_outage;
                std::this_thread::sleep_for(std::chrono::milliseconds(30));
            };
            results[k] = run_station(
                [&] { return open_study_store(uri_, options("st" + std::to_string(k))); },
                p, "out-" + std::string(1, char('a' + k)), 300 + k, after);
        });
    for (std::thread& t : threads) t.join();
    for (const StationResult& r : results) EXPECT_EQ(r.error, "");
    EXPECT_GE(journaled_during_outage.load(), 2);
    auto store = open_study_store(uri_, options("check"));
    expect_every_rating_once(*store, p, kStations);
}

TEST_F(Server, SnapshotHoldsEveryRowTheServerHolds) {
    init_study_store(uri_);
    const Protocol p = lucent::test::small_protocol();
    auto store = open_study_store(uri_, options("a"));
    const int64_t study = store->ensure_study(p);
    for (const char* code : {"P1", "P2"}) {
        int number = 0;
        const int64_t pid = store->ensure_participant(study, code, &number);
        const SessionRow s =
            store->create_session(study, pid, plan_trials(p, number, number), number, {});
        for (const TrialRow& t : store->trials(s.id))
            store->record_trial(s.id, t.id, lucent::test::outcome_for(p, t));
    }
    // Schema 5's tables: a withdrawal's tombstones; schema 9's: a declined code.
    {
        int number = 0;
        const int64_t pid = store->ensure_participant(study, "P3", &number);
        store->create_session(study, pid, plan_trials(p, number, number), number, {});
        ASSERT_TRUE(store->withdraw_participant("P3"));
        store->decline_consent(study, "P4", "a-page");
    }
    const ReadableStudyFile snapshot(uri_);
    Database copy(snapshot.path(), SQLITE_OPEN_READONLY);
    for (const char* table :
         {"studies", "stimuli", "stimulus_parameters", "participants", "sessions",
          "session_segments", "trials", "responses", "retired_participant_numbers",
          "withdrawn_sessions", "withdrawn_codes", "consent_declines", "declined_codes"})
        EXPECT_EQ(copy.scalar_int(std::string("SELECT count(*) FROM ") + table),
                  store->query_int(std::string("SELECT count(*) FROM ") + table))
            << table;
    EXPECT_EQ(copy.scalar_int("SELECT count(*) FROM withdrawn_sessions"), 1);
    EXPECT_EQ(copy.scalar_int("SELECT count(*) FROM declined_codes WHERE page_uuid = "
                              "'a-page'"),
              1);
    EXPECT_EQ(declined_consent_figure(copy), "1 participant code declined consent");
    // The ratings themselves, against the deterministic answers given.
    Statement s = copy.prepare(
        "SELECT t.position, r.question, r.rating, t.catch FROM responses r JOIN trials t "
        "ON "
        "t.id = r.trial_id");
    int checked = 0;
    while (s.step()) {
        const int q = s.text(1) == p.questions[0].id ? 0 : 1;
        const int expected =
            s.integer(3) ? 7
                         : lucent::test::rating_for(static_cast<int>(s.integer(0)), q);
        EXPECT_EQ(s.integer(2), expected);
        ++checked;
    }
    EXPECT_GT(checked, 0);
}

// Schema 9 on a server an older build left at schema 8: `lucent store init` adds
// declined_codes and keeps what schema 8 counted (per page) and the pages it kept
// declined; the report names both for what they are.
// Schema 10 on a server an older build left at schema 9: trials.kind's CHECK of the
// six built-in names is dropped (a kind is a registry entry), and only that one.
TEST_F(Server, ASchema9ServerMigratesDroppingOnlyTheKindCheck) {
    auto checks = [&] {
        pqxx::connection c(uri_);
        pqxx::work tx(c);
        std::set<std::string> names;
        for (const auto& row : tx.exec(
                 "SELECT conname FROM pg_constraint WHERE contype = 'c' AND conrelid = "
                 "'trials'::regclass"))
            names.insert(row[0].as<std::string>());
        return names;
    };
    lucent::test::migrate_server_to(uri_, 9);
    std::set<std::string> before = checks();
    ASSERT_TRUE(before.count("trials_kind_check")) << before.size();
    EXPECT_EQ(init_study_store(uri_), std::make_pair(9, kSchemaVersion));
    std::set<std::string> after = checks();
    before.erase("trials_kind_check");
    EXPECT_EQ(after, before);
    EXPECT_FALSE(after.empty());  // task's, skipped's... stay
}

TEST_F(Server, ASchema8ServerMigratesKeepingItsPageDeclinesBesideTheNewCodes) {
    lucent::test::migrate_server_to(uri_, 8);
    {
        pqxx::connection c(uri_);
        pqxx::work tx(c);
        tx.exec(R"sql(
INSERT INTO studies (id, name, protocol_text, protocol_hash, created_utc)
    VALUES (1, 's', 'x', 'h', 'now');
INSERT INTO consent_declines (study_id, declined) VALUES (1, 401);
INSERT INTO declined_pages (uuid) VALUES ('old-page');
)sql");
        tx.commit();
    }
    EXPECT_EQ(init_study_store(uri_), std::make_pair(8, kSchemaVersion));
    auto store = open_study_store(uri_, options("a"));
    EXPECT_EQ(store->query_int("SELECT declined FROM consent_declines"), 401);
    EXPECT_TRUE(store->consent_declined("old-page"));
    EXPECT_TRUE(store->decline_consent(1, "P1", "new-page"));
    EXPECT_FALSE(store->decline_consent(1, "P1", "newer-page"));
    EXPECT_TRUE(store->consent_declined("newer-page"));
    EXPECT_EQ(store->query_int("SELECT declined FROM consent_declines"), 401);
    const ReadableStudyFile snapshot(uri_);
    Database copy(snapshot.path(), SQLITE_OPEN_READONLY);
    EXPECT_EQ(declined_consent_figure(copy),
              "1 participant code declined consent, and 401 consent declines counted "
              "per page before schema 9 (page loads, not people)");
}

}  // namespace
}  // namespace lucent::study
