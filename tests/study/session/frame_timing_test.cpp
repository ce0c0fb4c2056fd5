#include "study/session/frame_timing.h"

#include <gtest/gtest.h>

namespace lucent::study {
namespace {

std::vector<int64_t> swaps(double hz, int n, int64_t start = 0) {
    std::vector<int64_t> out;
    for (int i = 0; i < n; ++i) out.push_back(start + static_cast<int64_t>(i * 1e9 / hz));
    return out;
}

TEST(FrameTiming, ZeroHzModeMeansUnknownNotInvented) {
    const RefreshEstimate e = estimate_refresh(0, swaps(60, 100));
    EXPECT_FALSE(e.mode_hz.has_value());
    EXPECT_FALSE(e.measured_hz.has_value());
    EXPECT_NE(e.note.find("unknown"), std::string::npos);
}

TEST(FrameTiming, MedianIntervalGivesTheRefreshAndOutliersDoNotMoveIt) {
    std::vector<int64_t> s = swaps(60, 100);
    s[50] += 30000000;  // one hitch
    for (size_t i = 51; i < s.size(); ++i) s[i] += 30000000;
    const RefreshEstimate e = estimate_refresh(60, s);
    ASSERT_TRUE(e.measured_hz.has_value());
    EXPECT_NEAR(*e.measured_hz, 60.0, 0.01);
    EXPECT_FALSE(e.mismatch);
}

TEST(FrameTiming, MoreThanFivePercentOffIsAWarning) {
    EXPECT_TRUE(estimate_refresh(60, swaps(144, 100)).mismatch);
    EXPECT_FALSE(estimate_refresh(60, swaps(58, 100)).mismatch);  // 3.3% off
    EXPECT_TRUE(estimate_refresh(60, swaps(56, 100)).mismatch);   // 6.7% off
    EXPECT_FALSE(estimate_refresh(60, swaps(60, 5)).measured_hz.has_value());
}

TEST(FrameTiming, DroppedFramesCountMissedVsyncs) {
    std::vector<int64_t> s = swaps(100, 10);  // 10 ms period
    EXPECT_EQ(dropped_frames(s, 100), 0);
    for (size_t i = 5; i < s.size(); ++i) s[i] += 20000000;  // interval of 3 periods
    EXPECT_EQ(dropped_frames(s, 100), 2);
    EXPECT_EQ(dropped_frames(s, 0), 0);
}

TEST(KeyPressTime, TheServersMillisecondBoundsAKeyThreadThatWokeLate) {
    constexpr int64_t kMs = 1'000'000;
    const int64_t t = 7'000'000 * kMs;  // 7000 s of steady clock
    const uint32_t ms = 7'000'000;
    // Received within the event's millisecond: the (sub-ms) receipt time.
    EXPECT_EQ(key_press_time(t + 300'000, ms), t + 300'000);
    // Received 4.2 ms after the event's millisecond began: the middle of it.
    EXPECT_EQ(key_press_time(t + 4 * kMs + 200'000, ms), t + kMs / 2);
    EXPECT_EQ(key_press_time(t + 999 * kMs, ms), t + kMs / 2);
    // Across the 32-bit wrap of the server's counter (every 49.7 days).
    const int64_t wrap = (int64_t(1) << 32) * kMs;
    EXPECT_EQ(key_press_time(wrap + 3 * kMs, 0xFFFFFFFFu), wrap - kMs + kMs / 2);
    // A server on another clock (remote, wall clock), or ahead of the receipt: the
    // receipt time, the only one known.
    EXPECT_EQ(key_press_time(t + 5 * kMs, 123), t + 5 * kMs);
    EXPECT_EQ(key_press_time(t + 5 * kMs, ms + 6), t + 5 * kMs);
    EXPECT_EQ(key_press_time(t + 1000 * kMs, ms), t + 1000 * kMs);
}

}  // namespace
}  // namespace lucent::study
