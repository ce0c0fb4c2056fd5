// ProgressBar output as a terminal would see it (forced), and its silence otherwise.
#include "renderer/core/progress.h"

#include <gtest/gtest.h>
#include <unistd.h>

namespace lucent {
namespace {

TEST(ProgressBar, ForcedBarShowsLabelPercentAndEndsWithOneNewline) {
    testing::internal::CaptureStderr();
    {
        ProgressBar bar("AO bake test", 200, {0.0, true});
        bar.update(100);
        bar.finish();
        bar.finish();  // idempotent
    }
    const std::string out = testing::internal::GetCapturedStderr();
    EXPECT_NE(out.find("AO bake test ["), std::string::npos) << out;
    EXPECT_NE(out.find(" 50%"), std::string::npos) << out;
    EXPECT_NE(out.find("100%"), std::string::npos) << out;
    EXPECT_EQ(out.find('\n'), out.size() - 1) << out;
}

TEST(ProgressBar, StaysSilentForShortWorkAndOffTerminals) {
    testing::internal::CaptureStderr();
    {
        ProgressBar quick("quick", 10, {60.0, true});  // shows only after a minute
        quick.update(5);
    }
    if (!isatty(STDERR_FILENO)) {
        ProgressBar piped("piped", 10, {0.0, false});
        auto callback = piped.callback();
        callback(5, 10);
    }
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace lucent
