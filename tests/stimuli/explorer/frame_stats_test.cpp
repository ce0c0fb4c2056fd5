#include "stimuli/explorer/frame_stats.h"

#include <gtest/gtest.h>

namespace lucent::explorer {
namespace {

TEST(FrameStats, SummarisesOnlyTheLastSecond) {
    FrameStats stats(1.0);
    EXPECT_EQ(stats.summary().frames, 0);
    stats.add(0.10, 100.0);  // drops out once a frame ends after 1.10
    stats.add(0.50, 10.0);
    stats.add(1.00, 20.0);
    stats.add(1.20, 30.0);
    const FrameTimeSummary s = stats.summary();
    EXPECT_EQ(s.frames, 3);
    EXPECT_DOUBLE_EQ(s.min_ms, 10.0);
    EXPECT_DOUBLE_EQ(s.max_ms, 30.0);
    EXPECT_DOUBLE_EQ(s.mean_ms, 20.0);
}

TEST(FrameStats, KeepsTheLatestFrameEvenWhenItIsSlowerThanTheWindow) {
    FrameStats stats(1.0);
    stats.add(1.0, 900.0);
    stats.add(5.0, 4000.0);
    const FrameTimeSummary s = stats.summary();
    EXPECT_EQ(s.frames, 1);
    EXPECT_DOUBLE_EQ(s.mean_ms, 4000.0);
}

}  // namespace
}  // namespace lucent::explorer
