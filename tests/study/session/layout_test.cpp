#include "study/session/layout.h"

#include <gtest/gtest.h>

namespace lucent::study {
namespace {

TEST(Layout, ImageIsCentredPixelForPixel) {
    const ScreenLayout l = compute_layout(1280, 1024, 128, 128, 3, 40);
    EXPECT_EQ(l.image.x, (1280 - 128) / 2);
    EXPECT_EQ(l.image.y, (1024 - 128) / 2);
    EXPECT_EQ(l.image.width, 128);
    EXPECT_EQ(l.image.height, 128);
    EXPECT_EQ(l.panel.y + l.panel.height, 1024);
}

TEST(Layout, LargeImagesMoveUpAboveThePanelButNotOffScreen) {
    const ScreenLayout l = compute_layout(1280, 1024, 512, 512, 3, 40);
    EXPECT_LE(l.image.y + l.image.height, l.panel.y);
    EXPECT_GE(l.image.y, 0);
    EXPECT_EQ(l.image.x, 384);
    const ScreenLayout huge = compute_layout(800, 600, 700, 700, 3, 40);
    EXPECT_EQ(huge.image.y, 0);
    EXPECT_EQ(huge.image.width, 700);  // never scaled
}

}  // namespace
}  // namespace lucent::study
