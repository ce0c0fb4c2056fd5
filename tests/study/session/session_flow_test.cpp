// The session state machine without GL: synthetic timestamped keys, a fake clock and a
// real study database in a scratch folder. Expected screen sequences are derived from
// the stored trial plan (practice flags, break_before), not from the flow itself.
#include "study/session/session_flow.h"

#include <gtest/gtest.h>

#include <memory>

#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

constexpr int64_t kMs = 1'000'000;

std::string small_with_screens(const std::string& base = lucent::test::kSmallProtocol) {
    return base + "\n[screens]\nconsent = \"Do you agree?\"\ninstructions = \"Rate.\"\n";
}

// One session of `protocol_text` in a fresh database, and a flow over it at t = 1 s.
class Flow : public ::testing::Test {
protected:
    void open(const std::string& protocol_text, bool consented = false) {
        protocol_ = parse_protocol(protocol_text, "flow.toml");
        dir_ = lucent::test::scratch_dir(
            std::string("flow_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        db_path_ = (dir_ / "s.db").string();
        store_ = std::make_unique<Store>(db_path_);
        const int64_t study = store_->ensure_study(protocol_);
        int number = 0;
        const int64_t pid = store_->ensure_participant(study, "P1", &number);
        session_ =
            store_->create_session(study, pid, plan_trials(protocol_, 5, number), 5, {});
        if (consented) store_->set_consent(session_.id);
        restart(consented);
    }
    // A new flow over the stored session (as a resumed run builds it).
    void restart(bool consented) {
        flow_ =
            std::make_unique<SessionFlow>(protocol_, *store_, session_.id,
                                          store_->trials(session_.id), consented, now_);
    }
    // One frame: the clock advances 16 ms, time passes for the flow, the frame is shown.
    void frame() {
        now_ += 16 * kMs;
        flow_->tick(now_);
        flow_->presented(flow_->serial(), now_);
    }
    // Frames until the flow leaves the blank and the stimulus is on screen.
    void until_rating() {
        for (int i = 0; i < 200 && !flow_->rating(); ++i) frame();
        ASSERT_NE(flow_->rating(), nullptr) << "no rating screen";
    }
    void press(Key key, int digit = 0, int64_t after_ms = 100) {
        now_ += after_ms * kMs;
        flow_->key({key, digit, now_});
    }
    // Answers the trial on screen: each question `value` (clamped to its scale), Enter.
    void answer(int value) {
        until_rating();
        for (const Question& q : protocol_.questions) {
            press(Key::Digit, std::min(value, q.points()));
            press(Key::Enter);
        }
    }
    std::string stored_status() {
        Database d(db_path_, SQLITE_OPEN_READONLY);
        Statement s = d.prepare("SELECT status, ended_utc IS NOT NULL FROM sessions");
        if (!s.step()) return "";
        return s.text(0) + (s.integer(1) ? "+ended" : "");
    }
    int64_t count(const std::string& sql) {
        return Database(db_path_, SQLITE_OPEN_READONLY).scalar_int(sql);
    }

    Protocol protocol_;
    std::filesystem::path dir_;
    std::string db_path_;
    std::unique_ptr<Store> store_;
    SessionRow session_;
    std::unique_ptr<SessionFlow> flow_;
    int64_t now_ = 1000 * kMs;
};

TEST_F(Flow, WalksConsentInstructionsPracticeTrialsBreaksAndDebrief) {
    open(small_with_screens());
    const std::vector<TrialRow> plan = store_->trials(session_.id);
    // The expected screens, from the stored plan alone.
    std::vector<Screen> expected = {Screen::Consent, Screen::Instructions};
    for (size_t i = 0; i < plan.size(); ++i) {
        if (i > 0 && plan[i - 1].practice && !plan[i].practice)
            expected.push_back(Screen::PracticeDone);
        else if (plan[i].break_before)
            expected.push_back(Screen::Break);
        expected.push_back(Screen::Trial);
    }
    expected.push_back(Screen::Debrief);
    ASSERT_NE(std::count(expected.begin(), expected.end(), Screen::Break), 0)
        << "plan has no break";

    std::vector<Screen> seen;  // each screen once, as it appears
    for (int step = 0; step < 2000 && !flow_->finished(); ++step) {
        frame();
        const Screen s = flow_->screen();
        if (s == Screen::Blank || (s == Screen::Trial && !flow_->rating())) continue;
        seen.push_back(s);
        if (s == Screen::Trial)
            answer(3);
        else
            press(Key::Enter);
    }
    EXPECT_EQ(seen, expected);
    EXPECT_TRUE(flow_->finished());
    EXPECT_EQ(flow_->result(), RunResult::Completed);
    EXPECT_EQ(stored_status(), "completed+ended");
    EXPECT_EQ(count("SELECT count(*) FROM responses"),
              static_cast<int64_t>(plan.size() * 2));
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE consent_utc IS NOT NULL"), 1);
}

TEST_F(Flow, TheLastConfirmCompletesTheSessionBeforeAnythingElseHappens) {
    open(lucent::test::kSmallProtocol, /*consented=*/true);
    const size_t n = flow_->total_trials();
    // Everything but the last trial answered straight in the store; the flow resumes.
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    for (size_t i = 0; i + 1 < n; ++i)
        store_->record_trial(session_.id, trials[i].id,
                             lucent::test::outcome_for(protocol_, trials[i]));
    restart(true);
    EXPECT_EQ(stored_status(), "running");
    answer(trials.back().is_catch ? 7 : 2);
    // A crash right here (no further call of any kind) must find it completed.
    flow_.reset();
    store_.reset();
    EXPECT_EQ(stored_status(), "completed+ended");
    EXPECT_EQ(count("SELECT count(*) FROM responses"), static_cast<int64_t>(n * 2));
}

TEST_F(Flow, EscapeQuitAndWindowCloseOnTheDebriefNeverReopenTheSession) {
    for (int how = 0; how < 3; ++how) {
        open(lucent::test::kSmallProtocol, true);
        const std::vector<TrialRow> trials = store_->trials(session_.id);
        for (const TrialRow& t : trials)
            if (&t != &trials.back())
                store_->record_trial(session_.id, t.id,
                                     lucent::test::outcome_for(protocol_, t));
        restart(true);
        answer(trials.back().is_catch ? 7 : 4);
        ASSERT_EQ(flow_->screen(), Screen::Debrief);
        frame();
        press(Key::Escape);
        EXPECT_FALSE(flow_->paused()) << "Escape paused the debrief";
        frame();
        if (how == 0) press(Key::Quit);
        if (how == 1) {
            press(Key::Escape);
            frame();
            press(Key::Quit);
        }
        if (how == 2) flow_->window_closed();
        if (how < 2) {
            EXPECT_FALSE(flow_->finished());
        }
        flow_->window_closed();
        EXPECT_TRUE(flow_->finished());
        EXPECT_EQ(flow_->result(), RunResult::Completed) << how;
        EXPECT_EQ(stored_status(), "completed+ended") << how;
        flow_.reset();
        store_.reset();
    }
}

TEST_F(Flow, KeysPressedBeforeAScreenAppearedAreDropped) {
    open(small_with_screens());
    frame();
    ASSERT_EQ(flow_->screen(), Screen::Consent);
    // A double Enter 30 ms apart, both seen in one poll before the next frame: the
    // second was pressed before the instructions were ever shown.
    now_ += 200 * kMs;
    flow_->key({Key::Enter, 0, now_ - 30 * kMs});
    flow_->key({Key::Enter, 0, now_});
    EXPECT_EQ(flow_->screen(), Screen::Instructions);
    frame();
    EXPECT_EQ(flow_->screen(), Screen::Instructions);
    // A key stamped before the frame that showed the screen does not count either.
    flow_->key({Key::Enter, 0, now_ - 1});
    EXPECT_EQ(flow_->screen(), Screen::Instructions);
    press(Key::Enter, 0, 1);
    EXPECT_EQ(flow_->screen(), Screen::Blank);
    // Digits before the stimulus onset do not answer.
    for (int i = 0; i < 200 && flow_->screen() == Screen::Blank; ++i) {
        flow_->presented(flow_->serial(), now_);
        now_ += 16 * kMs;
        flow_->tick(now_);
    }
    flow_->key({Key::Digit, 3, now_});  // trial entered, stimulus not yet shown
    frame();
    ASSERT_NE(flow_->rating(), nullptr);
    flow_->key({Key::Digit, 5, now_ - 1});  // pressed a moment before the onset
    EXPECT_FALSE(flow_->rating()->rating(0).has_value());
    press(Key::Digit, 6, 1);
    EXPECT_EQ(flow_->rating()->rating(0), 6);
}

TEST_F(Flow, AQuickDoubleEnterCannotSkipABreak) {
    std::string text = small_with_screens();
    text.replace(text.find("id = \"main\""), 11, "id = \"main\"\nrepeats = 3");
    open(text, true);
    // Resume at the trial just before the first break: all earlier trials answered.
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    size_t i = 1;
    while (i < trials.size() && !trials[i].break_before) ++i;
    ASSERT_LT(i, trials.size()) << "plan has no break";
    ASSERT_FALSE(trials[i - 1].practice);
    for (size_t k = 0; k + 1 < i; ++k)
        store_->record_trial(session_.id, trials[k].id,
                             lucent::test::outcome_for(protocol_, trials[k]));
    restart(true);
    until_rating();
    const Question& last = protocol_.questions.back();
    for (const Question& q : protocol_.questions) {
        press(Key::Digit, 2);
        if (&q != &last) press(Key::Enter);
    }
    // Confirm, and a second Enter 40 ms later, before the next frame shows the break.
    press(Key::Enter);
    flow_->key({Key::Enter, 0, now_ + 40 * kMs});
    now_ += 40 * kMs;
    EXPECT_EQ(flow_->screen(), Screen::Break);
    frame();
    EXPECT_EQ(flow_->screen(), Screen::Break) << "the break was skipped";
    press(Key::Enter);
    EXPECT_EQ(flow_->screen(), Screen::Blank);
}

TEST_F(Flow, BlankGivesWayToTheStimulusAfterTheInterTrialInterval) {
    open(lucent::test::kSmallProtocol, true);
    // No consent text: the (default) instructions screen first, then the first blank.
    ASSERT_EQ(flow_->screen(), Screen::Instructions);
    frame();
    press(Key::Enter);
    ASSERT_EQ(flow_->screen(), Screen::Blank);
    const int64_t entered = now_;
    const int64_t iti = protocol_.inter_trial_ms * kMs;
    flow_->tick(entered + iti - 1);
    EXPECT_EQ(flow_->screen(), Screen::Blank);
    flow_->tick(entered + iti);
    EXPECT_EQ(flow_->screen(), Screen::Trial);
    EXPECT_EQ(flow_->rating(), nullptr);  // until a frame shows the stimulus
    EXPECT_TRUE(flow_->awaiting_presentation());
    const int64_t onset = entered + iti + 7 * kMs;
    flow_->presented(flow_->serial(), onset);
    ASSERT_NE(flow_->rating(), nullptr);
    flow_->key({Key::Digit, 4, onset + 250 * kMs});
    flow_->key({Key::Enter, 0, onset + 300 * kMs});
    flow_->key({Key::Digit, 2, onset + 650 * kMs});
    flow_->key({Key::Enter, 0, onset + 900 * kMs});
    Database d(db_path_, SQLITE_OPEN_READONLY);
    EXPECT_EQ(d.scalar_int("SELECT onset_ns FROM trials WHERE position = 0"), onset);
    EXPECT_EQ(d.scalar_int("SELECT confirm_ns FROM trials WHERE position = 0"),
              onset + 900 * kMs);
    EXPECT_EQ(
        d.scalar_int("SELECT round(rt_ms) FROM responses WHERE question = 'translucent'"),
        250);
    EXPECT_EQ(
        d.scalar_int("SELECT round(rt_ms) FROM responses WHERE question = 'realistic'"),
        650);
}

TEST_F(Flow, PauseRestartsTheTrialAndQuitSavesItPaused) {
    open(lucent::test::kSmallProtocol, true);
    frame();
    press(Key::Enter);
    until_rating();
    press(Key::Digit, 5);
    press(Key::Escape);
    EXPECT_TRUE(flow_->paused());
    EXPECT_EQ(flow_->view().kind, ScreenView::Kind::Pause);
    flow_->key({Key::Enter, 0, now_ + kMs});  // before the pause screen was shown
    EXPECT_TRUE(flow_->paused());
    frame();
    press(Key::Resume);
    EXPECT_FALSE(flow_->paused());
    EXPECT_EQ(flow_->rating(), nullptr);  // a new onset, no answers kept
    frame();
    ASSERT_NE(flow_->rating(), nullptr);
    EXPECT_FALSE(flow_->rating()->rating(0).has_value());
    press(Key::Digit, 1, 300);  // 300 ms after the new onset
    press(Key::Enter);
    press(Key::Digit, 1);
    press(Key::Enter);
    // Timed from the new onset: neither the first showing nor the pause counts.
    EXPECT_EQ(count("SELECT round(rt_ms) FROM responses WHERE question = 'translucent'"),
              300);
    // Pause again on the next trial and quit: saved as paused, not ended.
    ASSERT_EQ(flow_->screen(), Screen::PracticeDone);  // the first trial was the practice
    frame();
    press(Key::Enter);
    until_rating();
    press(Key::Escape);
    frame();
    press(Key::Quit);
    EXPECT_TRUE(flow_->finished());
    EXPECT_EQ(flow_->result(), RunResult::SavedAndQuit);
    EXPECT_EQ(stored_status(), "paused");
}

TEST_F(Flow, WindowCloseMidSessionSavesAndADeclineBeforeConsentKeepsOnlyTheCount) {
    open(small_with_screens());
    frame();
    press(Key::Enter);
    frame();
    flow_->window_closed();
    EXPECT_EQ(flow_->result(), RunResult::SavedAndQuit);
    EXPECT_EQ(stored_status(), "paused");
    flow_.reset();
    store_.reset();
    open(small_with_screens());
    frame();
    press(Key::Decline);
    EXPECT_EQ(flow_->result(), RunResult::Declined);
    // Nothing of the person is kept: no session, trial, segment or participant; their
    // code once among those that declined, as a salted hash.
    EXPECT_EQ(stored_status(), "");
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 0);
    EXPECT_EQ(count("SELECT count(*) FROM trials"), 0);
    EXPECT_EQ(count("SELECT count(*) FROM session_segments"), 0);
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 1);
}

TEST_F(Flow, DecliningAResumedSessionThatHadConsentAbortsItAndKeepsItsAnswers) {
    open(small_with_screens(), true);
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    store_->record_trial(session_.id, trials[0].id,
                         lucent::test::outcome_for(protocol_, trials[0]));
    restart(false);  // a flow that shows the consent screen again
    frame();
    press(Key::Decline);
    EXPECT_EQ(flow_->result(), RunResult::Declined);
    EXPECT_EQ(stored_status(), "aborted+ended");
    EXPECT_EQ(count("SELECT count(*) FROM responses"),
              static_cast<int64_t>(protocol_.questions.size()));
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 0);
}

// Consent on record (an online enrolment writes it with the session) is not written
// again when the flow passes the consent screen: one write, its time kept.
TEST_F(Flow, ConsentAlreadyOnRecordIsNotWrittenAgain) {
    open(small_with_screens(), true);
    store_->db().exec("UPDATE sessions SET consent_utc = '2020-01-01T00:00:00.000Z'");
    restart(true);
    frame();
    ASSERT_EQ(flow_->screen(), Screen::Consent);
    press(Key::Enter);
    EXPECT_EQ(flow_->screen(), Screen::Instructions);
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE consent_utc = "
                    "'2020-01-01T00:00:00.000Z'"),
              1);
}

TEST_F(Flow, AResumedSessionStartsAtItsFirstOpenTrial) {
    open(lucent::test::kSmallProtocol, true);
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    store_->record_trial(session_.id, trials[0].id,
                         lucent::test::outcome_for(protocol_, trials[0]));
    store_->record_trial(session_.id, trials[1].id,
                         lucent::test::outcome_for(protocol_, trials[1]));
    restart(true);
    EXPECT_EQ(flow_->screen(), Screen::Blank);
    EXPECT_EQ(flow_->answered_trials(), 2u);
    EXPECT_EQ(flow_->trial()->id, trials[2].id);
    restart(
        false);  // no consent on record: from the start (no consent text: instructions)
    EXPECT_EQ(flow_->screen(), Screen::Instructions);
}

TEST_F(Flow, EachQuestionKeepsItsOwnScale) {
    open(lucent::test::mixed_scale_protocol_text(), true);
    frame();
    press(Key::Enter);
    until_rating();
    EXPECT_EQ(flow_->view().points, (std::vector<int>{7, 5}));
    press(Key::Digit, 7);  // 7 on the 7-point scale
    press(Key::Enter);
    press(Key::Digit, 7);  // beyond the 5-point scale: ignored
    press(Key::Enter);     // so Enter does not confirm
    EXPECT_FALSE(flow_->rating()->rating(1).has_value());
    press(Key::Right);  // the first arrow picks the middle of 1..5
    EXPECT_EQ(flow_->rating()->rating(1), 3);
    press(Key::Right);
    press(Key::Right);
    press(Key::Right);  // clamped at 5
    EXPECT_EQ(flow_->rating()->rating(1), 5);
    press(Key::Enter);
    EXPECT_EQ(count("SELECT rating FROM responses WHERE question = 'translucent'"), 7);
    EXPECT_EQ(count("SELECT rating FROM responses WHERE question = 'realistic'"), 5);
}

// Forced choices (issue 30): the arrows pick the alternative on their side, Enter
// confirms, and the stored choice is 1 or 2 of the screen order.
TEST_F(Flow, APairIsAnsweredWithTheArrowOfItsSideAndStoredAsThatAlternative) {
    open(lucent::test::kChoiceProtocol, true);
    // Walk to the first pair trial (the practice pair comes first).
    frame();
    press(Key::Enter);  // the (empty) instructions
    until_rating();
    const TrialRow* t = flow_->trial();
    ASSERT_NE(t, nullptr);
    ASSERT_EQ(t->task, Task::pair);
    EXPECT_EQ(flow_->choice_phase(), ChoicePhase::Answer);
    EXPECT_EQ(flow_->view().kind, ScreenView::Kind::Choice);
    const int64_t trial_id = t->id;
    press(Key::Left);
    press(Key::Right);  // a change of mind
    press(Key::Enter);
    Database d(db_path_, SQLITE_OPEN_READONLY);
    Statement s =
        d.prepare("SELECT question, rating, changes FROM responses WHERE trial_id = ?");
    s.bind(1, trial_id);
    ASSERT_TRUE(s.step());
    EXPECT_EQ(s.text(0), "more_translucent");
    EXPECT_EQ(s.integer(1), 2);
    EXPECT_EQ(s.integer(2), 1);
    EXPECT_FALSE(s.step());
}

TEST_F(Flow, ASequenceShowsEachPartForItsDurationBeforeItCanBeAnswered) {
    open(lucent::test::kChoiceProtocol, true);
    // Answer trials until an MLDS triad (sequential: 800 ms, 300 ms blank, 800 ms).
    for (int guard = 0; guard < 60; ++guard) {
        for (int i = 0; i < 200 && flow_->screen() != Screen::Trial; ++i) {
            if (flow_->screen() != Screen::Blank) press(Key::Enter);
            frame();
        }
        ASSERT_EQ(flow_->screen(), Screen::Trial);
        if (flow_->trial()->task == Task::triad) break;
        until_rating();
        press(Key::Digit, 1);
        press(Key::Enter);
    }
    ASSERT_EQ(flow_->trial()->task, Task::triad);
    const int64_t first_shown = now_;  // the frame that left the blank showed it
    EXPECT_EQ(flow_->choice_phase(), ChoicePhase::First);
    EXPECT_EQ(flow_->rating(), nullptr);
    press(Key::Left, 0, 10);  // too early: nothing to answer yet
    std::vector<std::pair<ChoicePhase, int64_t>> changes;
    for (int i = 0; i < 300 && !flow_->rating(); ++i) {
        const auto before = flow_->choice_phase();
        frame();
        if (flow_->choice_phase() != before)
            changes.emplace_back(*flow_->choice_phase(), now_);
    }
    ASSERT_EQ(changes.size(), 3u);
    EXPECT_EQ(changes[0].first, ChoicePhase::Gap);
    EXPECT_EQ(changes[1].first, ChoicePhase::Second);
    EXPECT_EQ(changes[2].first, ChoicePhase::Answer);
    // Each part lasted its duration, to within a frame (16 ms) of the fake display.
    EXPECT_GE(changes[0].second - first_shown, 800 * kMs);
    EXPECT_LT(changes[0].second - first_shown, (800 + 2 * 16) * kMs);
    EXPECT_GE(changes[1].second - changes[0].second, 300 * kMs);
    EXPECT_LT(changes[1].second - changes[0].second, (300 + 2 * 16) * kMs);
    EXPECT_GE(changes[2].second - changes[1].second, 800 * kMs);
    ASSERT_NE(flow_->rating(), nullptr);
    EXPECT_FALSE(flow_->rating()->rating(0).has_value());  // the early key did nothing
    const int64_t trial_id = flow_->trial()->id;
    flow_->click_choice(1, now_ + 5 * kMs);  // one click answers
    Database d(db_path_, SQLITE_OPEN_READONLY);
    Statement s = d.prepare(
        "SELECT r.question, r.rating, t.onset_ns FROM responses r JOIN trials t ON "
        "t.id = r.trial_id WHERE r.trial_id = ?");
    s.bind(1, trial_id);
    ASSERT_TRUE(s.step());
    EXPECT_EQ(s.text(0), "mlds");
    EXPECT_EQ(s.integer(1), 1);
    EXPECT_EQ(s.integer(2), first_shown);  // the onset is the first part's
}

TEST_F(Flow, AResumedSessionOfForcedChoicesShowsTheNextChoiceInItsPlannedScreenOrder) {
    open(lucent::test::kChoiceProtocol, true);
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    for (int i = 0; i < 5; ++i)
        store_->record_trial(session_.id, trials[i].id,
                             lucent::test::outcome_for(protocol_, trials[i]));
    restart(true);
    EXPECT_EQ(flow_->answered_trials(), 5u);
    ASSERT_NE(flow_->trial(), nullptr);
    EXPECT_EQ(flow_->trial()->id, trials[5].id);
    // The stored plan, not a new draw: the same task and stimuli on the same sides.
    const TrialPlan plan = plan_trials(protocol_, 5, 1);
    EXPECT_EQ(flow_->trial()->task, plan.trials[5].task);
    EXPECT_EQ(flow_->trial()->shown, plan.trials[5].shown);
}

}  // namespace
}  // namespace lucent::study
