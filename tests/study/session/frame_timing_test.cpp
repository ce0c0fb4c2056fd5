#include "session/frame_timing.h"

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

}  // namespace
}  // namespace lucent::study
