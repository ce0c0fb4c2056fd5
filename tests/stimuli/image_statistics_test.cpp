// Image statistics against hand-computable images and degenerate ones.
#include "stimuli/image_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lucent::stimuli {
namespace {

// A 4-channel image of grey pixels; alpha 1 for object pixels, 0 for background.
struct TestImage {
    int width, height;
    std::vector<float> values;
    TestImage(int w, int h) : width(w), height(h), values(std::size_t(w) * h * 4, 0.0f) {}
    void set(int p, float r, float g, float b, float a = 1.0f) {
        values[p * 4 + 0] = r;
        values[p * 4 + 1] = g;
        values[p * 4 + 2] = b;
        values[p * 4 + 3] = a;
    }
    FloatImageView view() const { return {width, height, 4, values}; }
};

TEST(ImageStatistics, LuminanceIsRec709OfLinearValues) {
    EXPECT_DOUBLE_EQ(luminance_rec709(1, 1, 1), 1.0);
    EXPECT_DOUBLE_EQ(luminance_rec709(0, 1, 0), 0.7152);
    EXPECT_DOUBLE_EQ(luminance_rec709(0, 0, 1), 0.0722);
}

TEST(ImageStatistics, TwoValuedHalfAndHalf) {
    // Half the object at 0.2, half at 0.6: mean 0.4, SD 0.2, contrast 0.5, skew 0.
    TestImage image(4, 2);
    for (int p = 0; p < 8; ++p)
        image.set(p, p % 2 ? 0.6f : 0.2f, p % 2 ? 0.6f : 0.2f, p % 2 ? 0.6f : 0.2f);
    const auto s = compute_image_statistics(image.view(), 10);
    EXPECT_EQ(s.object_pixels, 8u);
    EXPECT_NEAR(s.mean_luminance, 0.4, 1e-6);
    EXPECT_NEAR(s.sd_luminance, 0.2, 1e-6);
    EXPECT_NEAR(s.rms_contrast, 0.5, 1e-6);
    EXPECT_NEAR(s.skewness, 0.0, 1e-6);
    // Bins of width 0.1: 0.2 in bin 2, 0.6 in bin 6.
    EXPECT_EQ(s.luminance_histogram[2], 4u);
    EXPECT_EQ(s.luminance_histogram[6], 4u);
}

TEST(ImageStatistics, TwoValuedQuarterHasKnownSkew) {
    // A fraction p = 1/4 at 1, the rest at 0: mean 1/4, SD sqrt(p(1-p)), skew (1-2p)/SD.
    TestImage image(4, 4);
    for (int p = 0; p < 16; ++p) {
        const float v = p < 4 ? 1.0f : 0.0f;
        image.set(p, v, v, v);
    }
    const auto s = compute_image_statistics(image.view());
    const double sd = std::sqrt(0.25 * 0.75);
    EXPECT_NEAR(s.mean_luminance, 0.25, 1e-9);
    EXPECT_NEAR(s.sd_luminance, sd, 1e-9);
    EXPECT_NEAR(s.rms_contrast, sd / 0.25, 1e-9);
    EXPECT_NEAR(s.skewness, 0.5 / sd, 1e-9);
    EXPECT_EQ(s.luminance_histogram.front(), 12u);
    EXPECT_EQ(s.luminance_histogram.back(), 4u);  // 1.0 falls into the last bin
}

TEST(ImageStatistics, BackgroundIsLeftOut) {
    // Object pixels all 0.5; bright background pixels with alpha 0 must not count.
    TestImage image(3, 3);
    for (int p = 0; p < 9; ++p) image.set(p, 0.5f, 0.5f, 0.5f, p < 4 ? 1.0f : 0.0f);
    for (int p = 4; p < 9; ++p) image.set(p, 1.0f, 0.0f, 0.0f, 0.0f);
    const auto s = compute_image_statistics(image.view());
    EXPECT_EQ(s.object_pixels, 4u);
    EXPECT_NEAR(s.mean_luminance, 0.5, 1e-7);
    EXPECT_EQ(s.sd_luminance, 0.0);
    // An explicit mask overrides alpha.
    std::vector<std::uint8_t> mask(9, 0);
    mask[5] = mask[6] = 1;
    const auto masked = compute_image_statistics(image.view(), mask);
    EXPECT_EQ(masked.object_pixels, 2u);
    EXPECT_NEAR(masked.mean_luminance, 0.2126, 1e-7);
}

TEST(ImageStatistics, SaturationIntensityCorrelationSign) {
    // Brighter pixels less saturated: (I, S) = (0.2, 1) for pure red 0.6, then greys.
    TestImage image(2, 2);
    image.set(0, 0.6f, 0.0f, 0.0f);  // I = 0.2, S = 1
    image.set(1, 0.6f, 0.0f, 0.0f);
    image.set(2, 0.9f, 0.9f, 0.9f);  // I = 0.9, S = 0
    image.set(3, 0.9f, 0.9f, 0.9f);
    EXPECT_NEAR(compute_image_statistics(image.view()).saturation_intensity_correlation,
                -1.0, 1e-9);
    image.set(0, 0.3f, 0.3f, 0.3f);  // now the dim pixels are grey, the bright ones red
    image.set(1, 0.3f, 0.3f, 0.3f);
    image.set(2, 2.7f, 0.0f, 0.0f);
    image.set(3, 2.7f, 0.0f, 0.0f);
    EXPECT_NEAR(compute_image_statistics(image.view()).saturation_intensity_correlation,
                1.0, 1e-9);
}

TEST(ImageStatistics, EmptyMaskGivesZerosNotNaN) {
    TestImage image(2, 2);  // all alpha 0
    const auto s = compute_image_statistics(image.view());
    EXPECT_EQ(s.object_pixels, 0u);
    EXPECT_EQ(s.mean_luminance, 0.0);
    EXPECT_EQ(s.rms_contrast, 0.0);
    EXPECT_EQ(s.skewness, 0.0);
    EXPECT_EQ(s.saturation_intensity_correlation, 0.0);
    const auto empty = compute_image_statistics(FloatImageView{0, 0, 4, {}});
    EXPECT_EQ(empty.object_pixels, 0u);
}

TEST(ImageStatistics, ConstantAndBlackImagesAreFinite) {
    for (float v : {0.0f, 0.7f, 1e6f}) {
        TestImage image(8, 8);
        for (int p = 0; p < 64; ++p) image.set(p, v, v, v);
        const auto s = compute_image_statistics(image.view());
        EXPECT_EQ(s.sd_luminance, 0.0) << v;
        EXPECT_EQ(s.rms_contrast, 0.0) << v;  // mean 0 is guarded, not 0/0
        EXPECT_EQ(s.skewness, 0.0) << v;
        EXPECT_EQ(s.saturation_intensity_correlation, 0.0) << v;
    }
}

TEST(ImageStatistics, NonFinitePixelsAreSkippedAndSizesChecked) {
    TestImage image(2, 1);
    image.set(0, NAN, 0, 0);
    image.set(1, 0.5f, 0.5f, 0.5f);
    const auto s = compute_image_statistics(image.view());
    EXPECT_EQ(s.object_pixels, 1u);
    EXPECT_TRUE(std::isfinite(s.mean_luminance));
    EXPECT_THROW(compute_image_statistics(FloatImageView{3, 3, 4, image.values}),
                 std::invalid_argument);
}

}  // namespace
}  // namespace lucent::stimuli
