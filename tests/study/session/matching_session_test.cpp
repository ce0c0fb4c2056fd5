// Adjust and staircase trials through the session state machine (issue 31), without GL:
// a fake clock, a real study database, and the autopilot as a simulated observer with a
// known match bias and a known psychometric function. Expectations: the observer's own
// parameters (its bias), the up/down rule stated in PsychoPy's terms (checked on the
// stored track, not by re-running the engine), and the stored rows' arithmetic.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <optional>

#include "study/session/session_flow.h"
#include "study/web_series.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

constexpr int64_t kMs = 1'000'000;

const char* kProtocol = R"toml(
[study]
name = "matching_session"
inter_trial_ms = 100

[[stimuli]]
id = "thin"
technique = "empirical"
params = { thickness_exponent = 0.8 }

[[stimuli]]
id = "thick"
technique = "empirical"
params = { thickness_exponent = 2.5 }

[[stimuli]]
id = "match"
technique = "empirical"
params = { backlight = 0.6 }

[[blocks]]
id = "m"
task = "adjust"
stimuli = ["thin", "thick"]
match = "match"
knob = "thickness_exponent"
range = [0.2, 5.0]
scale = "log"
step = 0.05
fine_step = 0.002
repeats = 12
question = "Turn the right object until it looks like the left one."

[[blocks]]
id = "j"
task = "staircase"
stimuli = ["thin"]
knob = "thickness_exponent"
question = "Which looks more translucent?"

[[blocks.staircases]]
id = "a"
start = 0.6
n_up = 1
n_down = 3
step_sizes = [0.08, 0.04]
n_trials = 20
n_reversals = 6
max_delta = 2
max_trials = 80

[randomisation]
counterbalance_blocks = false
)toml";

class MatchingSession : public ::testing::Test {
protected:
    void SetUp() override { open(parse_protocol(kProtocol, "matching_session.toml")); }
    void open(Protocol protocol) {
        protocol_ = std::move(protocol);
        dir_ = lucent::test::scratch_dir(
            std::string("matching_session_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        db_ = (dir_ / "s.db").string();
        store_ = std::make_unique<Store>(db_);
        const int64_t study = store_->ensure_study(protocol_);
        int number = 0;
        const int64_t pid = store_->ensure_participant(study, "P1", &number);
        session_ =
            store_->create_session(study, pid, plan_trials(protocol_, 3, number), 3, {});
        store_->set_consent(session_.id);
        pilot_ = std::make_unique<Autopilot>(Autopilot::from_seed(17, 50.0));
        // A match 25 % too thick (log bias ln 1.25), noise 0.1 in log units; a
        // detection threshold of 0.3 with spread 0.1 and no lapses.
        pilot_->set_threshold_observers({0.3, 0.1, 0.0}, {std::log(1.25), 0.1, true});
        restart();
    }
    void restart() {
        flow_ = std::make_unique<SessionFlow>(protocol_, *store_, session_.id,
                                              store_->trials(session_.id), true, now_);
        if (series_) flow_->show_series(&*series_);
    }
    // Frames until `answered` trials are answered (or the flow ends).
    void run_until(size_t answered) {
        for (int frame = 0; frame < 400000 && !flow_->finished(); ++frame) {
            if (flow_->answered_trials() >= answered) return;
            now_ += 16 * kMs;
            flow_->tick(now_);
            flow_->presented(flow_->serial(), now_);
            for (const std::string& name : pilot_->due(now_, flow_->view()))
                flow_->key(autopilot_key(name, now_));
        }
    }
    Database read() { return Database(db_, SQLITE_OPEN_READONLY); }

    Protocol protocol_;
    std::filesystem::path dir_;
    std::string db_;
    std::unique_ptr<Store> store_;
    SessionRow session_;
    std::unique_ptr<Autopilot> pilot_;
    std::unique_ptr<SessionFlow> flow_;
    std::optional<WebSeries> series_;  // set: the browser's pre-rendered pictures
    int64_t now_ = 1'000'000'000;
};

TEST_F(MatchingSession, TheObserversMatchBiasIsWhatTheStoreHolds) {
    // Half way, the station quits and the session resumes: nothing changes.
    run_until(12);
    restart();
    run_until(1000);
    ASSERT_TRUE(flow_->finished());
    ASSERT_EQ(flow_->result(), RunResult::Completed);
    Database d = read();
    EXPECT_EQ(d.scalar_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              1);
    // 24 adjustments, each with its start, its final value and its changes.
    Statement s = d.prepare(
        "SELECT t.id, st.stimulus_key, t.start_value, t.final_value, r.rating, r.changes "
        "FROM trials t JOIN stimuli st ON st.id = t.stimulus_id JOIN responses r ON "
        "r.trial_id = t.id WHERE t.kind = 'adjust'");
    std::map<std::string, double> target = {{"thin", 0.8}, {"thick", 2.5}};
    double sum = 0;
    int n = 0;
    while (s.step()) {
        const double start = s.real(2), final_value = s.real(3);
        EXPECT_EQ(s.integer(4), 1);  // "confirmed"
        EXPECT_GE(final_value, 0.2);
        EXPECT_LE(final_value, 5.0);
        Statement a = d.prepare(
            "SELECT count(*), coalesce(max(step), 0) FROM adjustments WHERE trial_id = "
            "?");
        a.bind(1, s.integer(0));
        ASSERT_TRUE(a.step());
        EXPECT_EQ(a.integer(0), s.integer(5));  // every change, and only those
        EXPECT_EQ(a.integer(1), a.integer(0));
        if (a.integer(0) == 0) EXPECT_EQ(final_value, start);
        sum += std::log(final_value / target.at(s.text(1)));
        ++n;
    }
    ASSERT_EQ(n, 24);
    // The mean log ratio estimates ln 1.25 = 0.223: its standard error is 0.1/sqrt(24)
    // = 0.02, the fine step's rounding at most 0.002 * ln 10 / 2.
    EXPECT_NEAR(sum / n, std::log(1.25), 4 * 0.1 / std::sqrt(24.0) + 0.0024);
}

TEST_F(MatchingSession,
       AStaircaseFollowsItsRuleAcrossAResumeAndSkipsWhatItNoLongerNeeds) {
    // The adjust block first (no counterbalancing), then the staircase; the session
    // quits and resumes after every tenth staircase trial.
    run_until(24);
    for (size_t k = 34; !flow_->finished() && k < 400; k += 10) {
        run_until(k);
        restart();
    }
    ASSERT_EQ(flow_->result(), RunResult::Completed);
    Database d = read();
    Statement s = d.prepare(
        "SELECT t.intensity, r.rating = t.expected_rating FROM trials t JOIN responses r "
        "ON "
        "r.trial_id = t.id WHERE t.kind = 'staircase' ORDER BY t.position");
    std::vector<double> delta;
    std::vector<bool> correct;
    while (s.step()) {
        delta.push_back(s.real(0));
        correct.push_back(s.integer(1) == 1);
    }
    ASSERT_GE(delta.size(), 20u);
    // The rule, as PsychoPy states it (stated here, not run through the engine): until
    // the first reversal (a change against the previous change's direction) and for
    // that change itself, 1-up/1-down; after it, a wrong answer steps up and three
    // correct in a row since the last change step down. Steps are 0.08 or, from the
    // first reversal, 0.04.
    EXPECT_DOUBLE_EQ(delta[0], 0.6);
    int reversals = 0, last_direction = 0, run = 0;
    for (size_t i = 1; i < delta.size(); ++i) {
        const double change = delta[i] - delta[i - 1];
        run = correct[i - 1] ? run + 1 : 0;
        const int direction = change > 1e-12 ? 1 : change < -1e-12 ? -1 : 0;
        const bool reversal =
            direction != 0 && last_direction != 0 && direction != last_direction;
        const bool initial_rule = reversals == 0;
        SCOPED_TRACE("trial " + std::to_string(i + 1));
        // A step down may stop at the floor (min_delta 0) and stay there.
        const bool at_floor = delta[i] == 0.0;
        if (direction == 0) {
            EXPECT_TRUE(correct[i - 1] && (at_floor || (!initial_rule && run < 3)));
            continue;
        }
        EXPECT_EQ(direction > 0, !correct[i - 1]);
        if (direction < 0 && !initial_rule) EXPECT_GE(run, 3);
        const double size = std::abs(change);
        EXPECT_TRUE(std::abs(size - 0.08) < 1e-9 || at_floor ||
                    ((!initial_rule || reversal) && std::abs(size - 0.04) < 1e-9))
            << change;
        reversals += reversal ? 1 : 0;
        last_direction = direction;
        run = 0;
    }
    // The last answer has no trial after it, but it may reverse too: it finished the
    // staircase once n_trials and n_reversals were both met.
    const bool last_correct = correct.back();
    const int last_run = last_correct ? run + 1 : 0;
    if ((!last_correct && last_direction < 0) ||
        (last_correct && last_run >= 3 && last_direction > 0))
        ++reversals;
    // Finished at the first answer with both n_trials (20) and n_reversals (6) met.
    EXPECT_GE(reversals, 6);
    if (delta.size() > 20)
        EXPECT_EQ(reversals, 6);  // it went on past 20 trials only for the sixth
    else
        EXPECT_EQ(delta.size(), 20u);
    // Finished before its 80 slots: the rest were skipped, none answered twice.
    const int64_t answered = static_cast<int64_t>(delta.size());
    EXPECT_LT(answered, 80);
    EXPECT_EQ(d.scalar_int("SELECT count(*) FROM trials WHERE kind = 'staircase' AND "
                           "skipped = 1"),
              80 - answered);
    // The track settles near the observer's 79.4 % point of a 2AFC: the threshold
    // 0.3 + 0.1 * z where 0.5 + 0.5 * Phi(z) = 0.794, z = 0.54 -> 0.354; the last six
    // reversals' mean is within a few steps of it.
    EXPECT_GT(delta.back(), 0.354 - 3 * 0.08);
    EXPECT_LT(delta.back(), 0.354 + 3 * 0.08);
}

TEST_F(MatchingSession, InTheBrowserEveryValueShownAndStoredIsAPrerenderedPicture) {
    // A QUEST as well, whose proposals fall between the rungs of a 0.05 ladder.
    std::string text = kProtocol;
    text.insert(text.find("[randomisation]"), R"toml(
[[blocks.staircases]]
id = "q"
method = "quest"
start = 0.6
start_sd = 0.4
n_trials = 25
max_delta = 2
max_trials = 25
)toml");
    text.insert(text.find("[[blocks.staircases]]"), "ladder_step = 0.05\n");
    open(parse_protocol(text, "browser.toml"));
    series_ = web_series(protocol_);
    restart();
    run_until(30);
    restart();
    run_until(1000);
    ASSERT_EQ(flow_->result(), RunResult::Completed);
    Database d = read();
    // The adjust block's values: its series, 0.2 to 5 in 0.002 log10 steps: 700.
    const std::vector<double>& values = series_->find("m", "match")->steps;
    ASSERT_EQ(values.size(), 700u);
    Statement a = d.prepare(
        "SELECT t.start_value, t.final_value FROM trials t WHERE t.kind = 'adjust' UNION "
        "ALL SELECT a.value, a.value FROM adjustments a");
    int n = 0;
    while (a.step())
        for (const double v : {a.real(0), a.real(1)}) {
            EXPECT_EQ(v, values[nearest_step(values, v)]) << v;
            ++n;
        }
    EXPECT_GT(n, 48);
    // Every delta shown is a rung k * 0.05, and the QUEST's track is its own proposals
    // from the rungs it was told, each shown as the nearest rung: replayed here on a
    // fresh QUEST built from the protocol.
    const Block& j = *protocol_.find_block("j");
    const std::unique_ptr<adaptive::AdaptiveProcedure> quest =
        adaptive::make_procedure(j, j.procedures[1]);
    Statement s = d.prepare(
        "SELECT t.staircase, t.intensity, r.rating = t.expected_rating FROM trials t "
        "JOIN "
        "responses r ON r.trial_id = t.id WHERE t.kind = 'staircase' ORDER BY "
        "t.position");
    int quest_trials = 0;
    while (s.step()) {
        const double delta = s.real(1);
        EXPECT_NEAR(delta / 0.05, std::round(delta / 0.05), 1e-9) << delta;
        if (s.text(0) != "thin/q") continue;
        const double proposed = quest->next().intensity;
        EXPECT_NEAR(delta, 0.05 * std::round(proposed / 0.05), 1e-12)
            << "QUEST trial " << quest_trials + 1 << " proposed " << proposed;
        quest->add_response(s.integer(2) == 1, delta);
        ++quest_trials;
    }
    EXPECT_EQ(quest_trials, 25);
}

TEST_F(MatchingSession, TheBuiltInMatchingStudysObserverCarriesItsBiasInEveryBlock) {
    // Its targets are dipole renders, which have no thickness exponent: the simulated
    // observer takes the match stimulus's own r = 10 as what a target looks like, so
    // every block's matches centre on 10 x 1.25.
    open(builtin_protocol("matching"));
    run_until(1000);
    ASSERT_EQ(flow_->result(), RunResult::Completed);
    Database d = read();
    std::map<std::string, std::pair<double, int>> by_block;  // sum of ln(match / 10), n
    Statement s =
        d.prepare("SELECT block, final_value FROM trials WHERE kind = 'adjust'");
    while (s.step()) {
        auto& [sum, n] = by_block[s.text(0)];
        sum += std::log(s.real(1) / 10.0);
        ++n;
    }
    ASSERT_EQ(by_block.size(), 3u);
    for (const auto& [block, sum_n] : by_block) {
        const auto& [sum, n] = sum_n;
        EXPECT_EQ(n, 6) << block;
        // 6 matches: SE 0.1 / sqrt(6) = 0.041, the fine step's rounding 0.01 ln 10 / 2.
        EXPECT_NEAR(sum / n, std::log(1.25), 4 * 0.1 / std::sqrt(6.0) + 0.012) << block;
    }
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

TEST(AutopilotKey, EveryNameTheAutopilotUsesIsTheFlowsKey) {
    const TimedKey fine = autopilot_key("Shift+Left", 7);
    EXPECT_EQ(fine.key, Key::Left);
    EXPECT_TRUE(fine.shift);
    EXPECT_EQ(fine.t_ns, 7);
    const TimedKey three = autopilot_key("3", 0);
    EXPECT_EQ(three.key, Key::Digit);
    EXPECT_EQ(three.digit, 3);
    EXPECT_FALSE(three.shift);
    EXPECT_EQ(autopilot_key("Right", 0).key, Key::Right);
    EXPECT_EQ(autopilot_key("Up", 0).key, Key::Up);
    EXPECT_EQ(autopilot_key("Down", 0).key, Key::Down);
    EXPECT_EQ(autopilot_key("Escape", 0).key, Key::Escape);
    EXPECT_EQ(autopilot_key("Q", 0).key, Key::Quit);
    EXPECT_EQ(autopilot_key("R", 0).key, Key::Resume);
    EXPECT_EQ(autopilot_key("Enter", 0).key, Key::Enter);
    EXPECT_EQ(autopilot_key("0", 0).key, Key::Enter);  // not a key the flow knows
}

}  // namespace
}  // namespace lucent::study
