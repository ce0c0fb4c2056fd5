// The simulated participant's decisions and timing (the X side is tested end to end).
#include "study/session/autopilot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

// Runs the autopilot over a rating screen until it confirms; returns keys and times.
std::vector<std::pair<int64_t, std::string>> drive(Autopilot& a, ScreenView v) {
    std::vector<std::pair<int64_t, std::string>> out;
    int enters = 0;
    for (int64_t t = 0;
         t < 60'000'000'000LL && enters < static_cast<int>(v.points.size());
         t += 1'000'000) {
        for (const std::string& k : a.due(t, v)) {
            out.emplace_back(t, k);
            enters += k == "Enter";
        }
    }
    return out;
}

TEST(Autopilot, AnswersEveryStatementWithHumanLikeDelays) {
    Autopilot a = Autopilot::from_seed(5, 1.0);
    ScreenView v{ScreenView::Kind::Rating, 1, {7, 7, 7}, false, 0};
    const auto keys = drive(a, v);
    ASSERT_FALSE(keys.empty());
    EXPECT_EQ(std::count_if(keys.begin(), keys.end(),
                            [](auto& k) { return k.second == "Enter"; }),
              3);
    EXPECT_EQ(keys.back().second, "Enter");
    // A person needs hundreds of milliseconds per statement, not microseconds.
    EXPECT_GT(keys.front().first, 300'000'000);
    EXPECT_LT(keys.back().first, 20'000'000'000LL);
    for (const auto& [t, k] : keys) {
        if (k != "Enter") {
            EXPECT_TRUE(k >= "1" && k <= "7") << k;
        }
    }
}

// A key lost on its way to the window leaves the screen up: the participant presses
// again once the screen has stayed kPatienceNs after its last key, not before, and a
// blank screen (nothing to answer) is only waited on.
TEST(Autopilot, AScreenStillShownAfterItsKeysIsAnsweredAgain) {
    Autopilot a = Autopilot::from_seed(11, 12.0);
    const ScreenView text{ScreenView::Kind::Text, 4, {}, false, 0};
    std::vector<int64_t> enters;
    const int64_t step = 1'000'000;
    for (int64_t t = 0; t < 12'000'000'000LL; t += step)
        for (const std::string& k : a.due(t, text))
            if (k == "Enter") enters.push_back(t);
    ASSERT_EQ(enters.size(), 3u);  // the first press, then once per patience
    EXPECT_EQ(a.presses_again(), 2);
    EXPECT_GE(enters[1] - enters[0], Autopilot::kPatienceNs);
    EXPECT_LT(enters[1] - enters[0], Autopilot::kPatienceNs + 2'000'000'000LL);
    // A new screen is planned afresh: no press again before its own patience.
    const ScreenView next{ScreenView::Kind::Text, 5, {}, false, 0};
    int next_enters = 0;
    for (int64_t t = 12'000'000'000LL; t < 16'000'000'000LL; t += step)
        for (const std::string& k : a.due(t, next)) next_enters += k == "Enter";
    EXPECT_EQ(next_enters, 1);
    EXPECT_EQ(a.presses_again(), 2);
    Autopilot waiting = Autopilot::from_seed(11, 12.0);
    const ScreenView blank{ScreenView::Kind::Blank, 1, {}, false, 0};
    for (int64_t t = 0; t < 20'000'000'000LL; t += 10 * step)
        EXPECT_TRUE(waiting.due(t, blank).empty());
    EXPECT_EQ(waiting.presses_again(), 0);
}

TEST(Autopilot, CatchTrialsGetTheExpectedAnswerAndSpeedScalesDelays) {
    Autopilot slow = Autopilot::from_seed(9, 1.0), fast = Autopilot::from_seed(9, 10.0);
    ScreenView v{ScreenView::Kind::Rating, 1, {7, 7}, true, 7};
    const auto s = drive(slow, v), f = drive(fast, v);
    for (const auto& [t, k] : s) EXPECT_TRUE(k == "7" || k == "Enter");
    ASSERT_EQ(s.size(), f.size());
    EXPECT_NEAR(static_cast<double>(f.back().first), s.back().first / 10.0, 2e6);
}

TEST(Autopilot, MixedScalesGetRatingsWithinEachQuestionsOwnScale) {
    // 7 points then 5, and the other order: over many seeded screens every digit lies
    // on its question's scale, and the whole range of each scale is used.
    for (const std::vector<int>& points :
         {std::vector<int>{7, 5}, std::vector<int>{5, 7}}) {
        std::vector<std::set<int>> used(2);
        for (uint64_t seed = 0; seed < 200; ++seed) {
            Autopilot a = Autopilot::from_seed(seed, 50.0);
            size_t question = 0;
            for (const auto& [t, k] :
                 drive(a, ScreenView{ScreenView::Kind::Rating, 1, points, false, 0})) {
                if (k == "Enter") {
                    ++question;
                    continue;
                }
                const int digit = std::stoi(k);
                ASSERT_LT(question, points.size());
                EXPECT_GE(digit, 1);
                EXPECT_LE(digit, points[question])
                    << "question " << question << " of " << points[0];
                used[question].insert(digit);
            }
        }
        for (size_t q = 0; q < 2; ++q) EXPECT_EQ(used[q].size(), size_t(points[q])) << q;
    }
}

TEST(Autopilot, ScriptsPlayInOrderAndBadLinesNameTheLine) {
    const auto dir = lucent::test::scratch_dir("autopilot_script");
    const std::string good = (dir / "good.txt").string(),
                      bad = (dir / "bad.txt").string();
    std::ofstream(good) << "# consent\n100 Enter\n50 3\n\n10 Escape\n";
    std::ofstream(bad) << "100 Enter\n20 Space\n";
    Autopilot a = Autopilot::from_argument(good, 1.0);
    EXPECT_TRUE(a.scripted());
    using Script = std::vector<std::pair<double, std::string>>;
    EXPECT_EQ(a.script(), (Script{{100, "Enter"}, {50, "3"}, {10, "Escape"}}));
    EXPECT_TRUE(a.due(1'000'000'000, ScreenView{}).empty());  // played by the X server
    try {
        Autopilot::from_file(bad);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.txt:2:"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(Autopilot::from_argument("42", 1.0).scripted());
}

// `lucent run --autopilot-match BIAS,NOISE[,log]` and `--autopilot-detection T,S[,L]`.
TEST(Autopilot, TheThresholdObserversParseFromTheCommandLine) {
    const MatchObserver m = MatchObserver::parse("0.2,0.05,log");
    EXPECT_DOUBLE_EQ(m.bias, 0.2);
    EXPECT_DOUBLE_EQ(m.noise, 0.05);
    EXPECT_TRUE(m.log_scale);
    const MatchObserver linear = MatchObserver::parse("-0.5,0");
    EXPECT_DOUBLE_EQ(linear.bias, -0.5);
    EXPECT_FALSE(linear.log_scale);
    EXPECT_THROW(MatchObserver::parse("0.2"), std::invalid_argument);
    EXPECT_THROW(MatchObserver::parse("0.2,0.1,0.3"), std::invalid_argument);
    EXPECT_THROW(MatchObserver::parse("0.2,-1"), std::invalid_argument);
    EXPECT_THROW(MatchObserver::parse("a,1,log"), std::invalid_argument);
    const DetectionObserver d = DetectionObserver::parse("0.3,0.1,0.02");
    EXPECT_DOUBLE_EQ(d.threshold, 0.3);
    EXPECT_DOUBLE_EQ(d.lapse, 0.02);
}

// --autopilot-adjust wheel|drag: the pointer events that take the match to its goal.
// A log knob over [0.2, 5] (log10 range 1.39794), steps 0.05 / 0.01 on log10, from 0.5
// to 1.1: log10(2.2) = 0.34242 is 6 coarse steps (0.30) and 4 fine ones (0.04242).
AdjustView log_view() {
    AdjustView v;
    v.value = 0.5;
    v.lo = 0.2;
    v.hi = 5.0;
    v.step = 0.05;
    v.fine_step = 0.01;
    v.log_scale = true;
    return v;
}

std::vector<std::string> repeated(const std::string& name, int n,
                                  std::vector<std::string> then = {}) {
    std::vector<std::string> out(n, name);
    out.insert(out.end(), then.begin(), then.end());
    return out;
}

TEST(Autopilot, WheelNotchesAreWholeCoarseStepsThenFineKeys) {
    EXPECT_EQ(adjust_wheel(log_view(), 1.1),
              repeated("WheelUp", 6, repeated("Shift+Right", 4)));
    // Linear [0, 1], steps 0.1 / 0.01, from 0.9 down to 0.23: 0.67 is 6 notches
    // and 7 fine steps.
    AdjustView v;
    v.value = 0.9;
    v.step = 0.1;
    v.fine_step = 0.01;
    EXPECT_EQ(adjust_wheel(v, 0.23), repeated("WheelDown", 6, repeated("Shift+Left", 7)));
    EXPECT_TRUE(adjust_wheel(v, std::nan("")).empty());
}

TEST(Autopilot, ADragCrossesTheMatchByTheGoalsShareOfItsWidth) {
    // The 64-pixel match at (652, 480): 0.34242 / 1.39794 of 64 px is 15.68, so 16 px,
    // centred on the match (676 -> 692) along its middle row (480 + 32), the pointer
    // on the match before the press. 16 px move log10 by 0.349485, from -0.30103 to
    // 0.048455: 0.00706 past log10(1.1) = 0.041393, one fine step back.
    AdjustView v = log_view();
    v.match = Rect{652, 480, 64, 64};
    EXPECT_EQ(adjust_drag(v, 1.1),
              (std::vector<std::string>{"Move:676,512", "Press:676,512", "Move:692,512",
                                        "Release", "Shift+Left"}));
    // Linear [0, 1] on a 200-pixel match at (100, 50): 0.9 to 0.2 is -140 px, centred
    // (270 -> 130) at row 100, landing on the goal: no keys after it.
    AdjustView lin;
    lin.value = 0.9;
    lin.match = Rect{100, 50, 200, 100};
    EXPECT_EQ(adjust_drag(lin, 0.2),
              (std::vector<std::string>{"Move:270,100", "Press:270,100", "Move:130,100",
                                        "Release"}));
    // Less than half a pixel away: no drag, only the fine steps (0.002 of 0.01: none).
    EXPECT_TRUE(adjust_drag(lin, 0.902).empty());
    // Without the match's place, the keys.
    lin.match.reset();
    EXPECT_EQ(adjust_drag(lin, 0.2), adjust_keys(lin, 0.2));
}

TEST(Autopilot, PointerEventsComeOnePerFrameAtLeastTwoFramesApart) {
    EXPECT_EQ(parse_adjust_by("wheel"), AdjustBy::wheel);
    EXPECT_EQ(parse_adjust_by("drag"), AdjustBy::drag);
    EXPECT_EQ(parse_adjust_by("keys"), AdjustBy::keys);
    EXPECT_FALSE(parse_adjust_by("mouse"));
    ScreenView v;
    v.kind = ScreenView::Kind::Adjust;
    v.serial = 1;
    v.adjust = log_view();
    v.adjust.target = 1.1;  // the default match observer: no bias, no noise
    v.adjust.match = Rect{652, 480, 64, 64};
    for (const AdjustBy by : {AdjustBy::wheel, AdjustBy::drag}) {
        SCOPED_TRACE(by == AdjustBy::wheel ? "wheel" : "drag");
        std::vector<std::string> expected = by == AdjustBy::wheel
                                                ? adjust_wheel(v.adjust, 1.1)
                                                : adjust_drag(v.adjust, 1.1);
        expected.push_back("Enter");
        // Fast (speed 100: 1.2 ms between moves), in 16 ms frames: each pointer event
        // still two frames or more after the one before.
        Autopilot a = Autopilot::from_seed(3, 100.0);
        a.set_adjust_by(by);
        std::vector<std::string> events;
        int64_t last_pointer = -1'000'000'000;
        for (int64_t t = 0; t < 10'000'000'000LL; t += 16'000'000) {
            for (const std::string& e : a.due(t, v)) {
                events.push_back(e);
                if (!is_pointer_event(e)) continue;
                EXPECT_GE(t - last_pointer, 32'000'000) << e;
                last_pointer = t;
            }
            if (!events.empty() && events.back() == "Enter") break;
        }
        EXPECT_EQ(events, expected);
        // A frame late enough for all of them (a slow render): one pointer event per
        // frame, the keys after the last one two frames after it (the runner applies
        // pointer events while drawing the next frame, keys before drawing).
        Autopilot late = Autopilot::from_seed(3, 100.0);
        late.set_adjust_by(by);
        late.due(0, v);  // the screen appears
        std::vector<size_t> per_frame;
        events.clear();
        for (int frame = 0; frame < 20 && (events.empty() || events.back() != "Enter");
             ++frame) {
            const std::vector<std::string> due = late.due(10'000'000'000LL, v);
            per_frame.push_back(due.size());
            events.insert(events.end(), due.begin(), due.end());
        }
        EXPECT_EQ(events, expected);
        const std::vector<size_t> wheel_frames = {1, 1, 1, 1, 1, 1, 0, 5},
                                  drag_frames = {1, 1, 1, 1, 0, 2};
        EXPECT_EQ(per_frame, by == AdjustBy::wheel ? wheel_frames : drag_frames);
    }
}
}  // namespace
}  // namespace lucent::study
