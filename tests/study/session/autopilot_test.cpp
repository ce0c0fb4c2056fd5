// The simulated participant's decisions and timing (the X side is tested end to end).
#include "study/session/autopilot.h"

#include <gtest/gtest.h>

#include <algorithm>
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

}  // namespace
}  // namespace lucent::study
