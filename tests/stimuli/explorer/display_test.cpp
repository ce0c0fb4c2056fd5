// Display encodings of the explorer's view (no GL needed): shaded images go to 8-bit sRGB
// like PNG output, depth buffers to grey with near bright, far dark, background black.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/srgb.h"
#include "stimuli/explorer/view_renderer.h"

namespace lucent::explorer {
namespace {

TEST(Display, ShadedImageIsClampedSrgbWithOpaqueAlpha) {
    Image image(5, 1);
    image.set(0, 0, {0.f, 1.f, 0.5f, 0.f});
    image.set(1, 0, {std::numeric_limits<float>::quiet_NaN(), 7.f, -1.f, 1.f});
    image.set(2, 0, {0.0031308f, 0.2f, 0.8f, 1.f});
    const auto bytes = encode_for_display(image);
    ASSERT_EQ(bytes.size(), 20u);
    EXPECT_EQ(bytes[0], 0);
    EXPECT_EQ(bytes[1], 255);
    EXPECT_EQ(bytes[2], 188);  // IEC 61966-2-1: 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
    EXPECT_EQ(bytes[3], 255);
    EXPECT_EQ(bytes[4], 0);  // NaN never reaches the screen
    EXPECT_EQ(bytes[5], 255);
    EXPECT_EQ(bytes[6], 0);
    EXPECT_EQ(bytes[8], 10);    // 12.92 * 0.0031308 * 255 = 10.3 (linear segment)
    EXPECT_EQ(bytes[9], 124);   // 0.2 -> 0.4845
    EXPECT_EQ(bytes[10], 231);  // 0.8 -> 0.9063
}

// The explorer shows what `lucent render` writes: every value of a fine ramp gets the
// code of the formula a PNG stores, lround(srgb_encode(v) * 255) (a coarser table
// rounded the value first and missed codes near each transition).
TEST(Display, EveryValueGetsTheCodeAPngStores) {
    const int n = 200'000;
    Image ramp(n, 1);
    for (int i = 0; i < n; ++i) {
        const float v = float(i) / float(n - 1);
        ramp.set(i, 0, {v, v * v, 1.0f - v, 1.f});
    }
    const auto bytes = encode_for_display(ramp);
    int differ = 0;
    for (int i = 0; i < n * 4; ++i) {
        if (i % 4 == 3) continue;
        const float v = ramp.rgba[std::size_t(i)];
        differ += bytes[std::size_t(i)] != std::lround(common::srgb_encode(v) * 255.0f);
    }
    EXPECT_EQ(differ, 0);
}

TEST(Display, DepthIsGreyNearBrightFarDarkBackgroundBlack) {
    const auto bytes = depth_for_display({1.f, 0.2f, 0.6f, 0.4f});
    EXPECT_EQ(bytes[0], 0);                                            // background
    EXPECT_EQ(bytes[4], 255);                                          // nearest
    EXPECT_EQ(bytes[8], static_cast<int>(std::lround(0.15 * 255)));    // farthest
    EXPECT_EQ(bytes[12], static_cast<int>(std::lround(0.575 * 255)));  // halfway
    EXPECT_EQ(bytes[12], bytes[13]);
    EXPECT_EQ(bytes[15], 255);
}

}  // namespace
}  // namespace lucent::explorer
