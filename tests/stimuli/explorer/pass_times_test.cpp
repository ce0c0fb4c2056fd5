// The status bar's per-pass times: a pass that was not re-run shows as cached.
#include "stimuli/explorer/pass_times.h"

#include <gtest/gtest.h>

namespace lucent::explorer {
namespace {

TEST(PassTimes, CachedPassesShowAsCachedAndTheCountOfPassesThatRan) {
    gl::FrameTimings timings;
    timings.gpu_timer = true;
    timings.passes = {{"ambient_occlusion", 0.0, true},
                      {"front_depth", 0.0, true},
                      {"shade", 1.234, false}};
    EXPECT_EQ(
        pass_times_text(timings),
        "GPU pass times (timer queries):  ambient_occlusion cached  front_depth cached"
        "  shade 1.23 ms  (1 of 3 passes ran)");
    timings.gpu_timer = false;
    timings.passes = {{"shade", 0.5, false}};
    EXPECT_EQ(pass_times_text(timings),
              "pass times (wall, glFinish):  shade 0.50 ms  (1 of 1 passes ran)");
}

}  // namespace
}  // namespace lucent::explorer
