// The sRGB transfer function against IEC 61966-2-1's closed form: the linear segment up
// to 0.0031308 (encoded 0.04045), 1.055 v^(1/2.4) - 0.055 above it, and back.
#include "common/srgb.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lucent::common {
namespace {

TEST(Srgb, EncodesTheEndsAndTheMiddle) {
    EXPECT_EQ(srgb_encode(0.0), 0.0);
    EXPECT_EQ(srgb_encode(0.0f), 0.0f);
    EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-15);
    EXPECT_NEAR(srgb_encode(1.0f), 1.0f, 1e-6f);
    // 1.055 * 0.5^(1/2.4) - 0.055 = 0.735356983...: 8-bit code 188.
    EXPECT_NEAR(srgb_encode(0.5), 0.735356983, 1e-9);
    EXPECT_NEAR(srgb_encode(0.5f), 0.735356983f, 1e-6f);
    EXPECT_EQ(std::lround(srgb_encode(0.5) * 255), 188);
}

TEST(Srgb, TheTwoSegmentsMeetAtTheBoundary) {
    // At and below 0.0031308 the encoding is 12.92 v.
    EXPECT_NEAR(srgb_encode(0.0031308), 12.92 * 0.0031308, 1e-15);
    EXPECT_NEAR(srgb_encode(0.001), 0.01292, 1e-15);
    // Just above, the power segment continues it (to 3e-8: the standard's rounded
    // constants leave that gap).
    EXPECT_NEAR(srgb_encode(std::nextafter(0.0031308, 1.0)), 12.92 * 0.0031308, 1e-7);
    EXPECT_NEAR(srgb_decode(0.04045), 0.04045 / 12.92, 1e-15);
    EXPECT_NEAR(srgb_decode(std::nextafter(0.04045, 1.0)), 0.04045 / 12.92, 1e-8);
}

TEST(Srgb, DecodesTheClosedForm) {
    EXPECT_EQ(srgb_decode(0.0), 0.0);
    EXPECT_NEAR(srgb_decode(1.0), 1.0, 1e-15);
    EXPECT_NEAR(srgb_decode(0.735356983), 0.5, 1e-9);
    EXPECT_NEAR(srgb_decode(0.735356983f), 0.5f, 1e-6f);
    // ((0.5 + 0.055) / 1.055)^2.4 = 0.214041140...
    EXPECT_NEAR(srgb_decode(0.5), 0.214041140, 1e-9);
}

TEST(Srgb, ClampsToTheUnitRange) {
    EXPECT_EQ(srgb_encode(-1.0), 0.0);
    EXPECT_NEAR(srgb_encode(2.0), 1.0, 1e-15);
    EXPECT_EQ(srgb_decode(-0.5f), 0.0f);
    EXPECT_NEAR(srgb_decode(7.0f), 1.0f, 1e-6f);
    EXPECT_TRUE(std::isnan(srgb_encode(std::nan(""))));
}

TEST(Srgb, DecodeInvertsEncode) {
    for (int i = 0; i <= 1000; ++i) {
        const double v = i / 1000.0;
        EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, 1e-12) << v;
        EXPECT_NEAR(srgb_decode(srgb_encode(float(v))), float(v), 2e-6f) << v;
    }
}

}  // namespace
}  // namespace lucent::common
