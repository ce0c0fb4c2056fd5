// Image output: formats, encodings, atomic writes, and no NaN/Inf ever written.
#include "core/image.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/image_compare.h"
#include "test_paths.h"

namespace lucent {
namespace {

Image gradient() {
    Image image(4, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) image.set(x, y, {x / 3.0f, y / 2.0f, 0.5f, 1.0f});
    return image;
}

TEST(ImageIo, ExrRoundTripsLinearFloatsExactly) {
    const auto dir = test::scratch_dir("image_exr");
    Image image = gradient();
    image.set(1, 1,
              {2.5f, -0.25f, 1e-8f, 0.0f});  // HDR, negative and tiny values survive
    write_image(dir / "a.exr", image);
    const Image back = read_image(dir / "a.exr");
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 3);
    EXPECT_EQ(back.rgba, image.rgba);
}

TEST(ImageIo, PngIsEightBitSrgbUnlessLinear) {
    const auto dir = test::scratch_dir("image_png");
    Image image(2, 1);
    image.set(0, 0, {0.5f, 0.0f, 1.0f, 1.0f});
    image.set(1, 0, {0.0031308f, 2.0f, -1.0f, 1.0f});
    write_image(dir / "s.png", image);
    write_image(dir / "l.png", image, {.linear = true});
    const Image srgb = read_image(dir / "s.png"), linear = read_image(dir / "l.png");
    // sRGB(0.5) = 1.055 * 0.5^(1/2.4) - 0.055 = 0.735357 -> 188/255.
    EXPECT_FLOAT_EQ(srgb.at(0, 0).r, 188.0f / 255.0f);
    EXPECT_FLOAT_EQ(srgb.at(1, 0).r, std::round(0.0031308f * 12.92f * 255.0f) / 255.0f);
    EXPECT_FLOAT_EQ(srgb.at(1, 0).g, 1.0f);  // clamped
    EXPECT_FLOAT_EQ(srgb.at(1, 0).b, 0.0f);
    EXPECT_FLOAT_EQ(linear.at(0, 0).r, 128.0f / 255.0f);
}

TEST(ImageIo, TiffIsSixteenBit) {
    const auto dir = test::scratch_dir("image_tif");
    Image image(1, 1);
    image.set(0, 0, {0.5f, 0.25f, 0.125f, 1.0f});
    write_image(dir / "a.tif", image, {.linear = true});
    const Image back = read_image(dir / "a.tif");
    EXPECT_FLOAT_EQ(back.at(0, 0).r, 32768.0f / 65535.0f);  // 16-bit step, not 8-bit
    EXPECT_FLOAT_EQ(back.at(0, 0).g, 16384.0f / 65535.0f);
}

TEST(ImageIo, NonFiniteValuesAreNeverWritten) {
    const auto dir = test::scratch_dir("image_nan");
    Image image(3, 1);
    const float inf = std::numeric_limits<float>::infinity();
    image.set(0, 0, {std::nanf(""), inf, -inf, 1.0f});
    image.set(1, 0, {0.5f, 0.5f, 0.5f, std::nanf("")});
    Image copy = image;
    EXPECT_EQ(count_non_finite_pixels(image), 2u);  // per pixel: (0,0) and (1,0)
    EXPECT_EQ(replace_non_finite(copy), 4u);        // per value
    EXPECT_EQ(count_non_finite_pixels(copy), 0u);
    EXPECT_EQ(copy.at(0, 0).r, 0.0f);
    EXPECT_EQ(copy.at(0, 0).g, std::numeric_limits<float>::max());
    EXPECT_EQ(copy.at(0, 0).b, -std::numeric_limits<float>::max());
    for (const char* name : {"n.exr", "n.png", "n.tif"}) {
        write_image(dir / name, image);
        const Image back = read_image(dir / name);
        for (float v : back.rgba) EXPECT_TRUE(std::isfinite(v)) << name;
    }
    EXPECT_EQ(read_image(dir / "n.exr").at(0, 0).r, 0.0f);
}

TEST(ImageIo, UnsupportedExtensionNamesTheFileAndWritesNothing) {
    const auto dir = test::scratch_dir("image_bad");
    try {
        write_image(dir / "a.jpg", gradient());
        FAIL();
    } catch (const ImageError& e) {
        EXPECT_NE(std::string(e.what()).find("a.jpg: unsupported image format '.jpg'"),
                  std::string::npos);
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir));
    EXPECT_THROW(read_image(dir / "missing.exr"), ImageError);
}

}  // namespace
}  // namespace lucent

namespace lucent {
namespace {

TEST(ImageCompare, SkipsTheSilhouetteBandAndMeasuresTheRest) {
    // 8x8: left half covered in both; b differs by 0.1 in red everywhere and has one
    // extra covered column (a silhouette mismatch that must be skipped).
    Image a(8, 8), b(8, 8);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            a.set(x, y, {0.5f, 0.5f, 0.5f, x < 4 ? 1.0f : 0.0f});
            b.set(x, y, {0.6f, 0.5f, 0.5f, x < 5 ? 1.0f : 0.0f});
        }
    const ImageErrorStats all = compare_images(a, b, 0);
    EXPECT_EQ(all.pixels, 64u);
    EXPECT_NEAR(all.mean, 0.1 / 3.0, 1e-6);
    EXPECT_NEAR(all.rmse, std::sqrt(0.01 / 3.0), 1e-6);
    EXPECT_NEAR(all.p99, 0.1, 1e-6);
    // Band 1: columns 3..5 touch a coverage change in a or b, or differ between them.
    const ImageErrorStats banded = compare_images(a, b, 1);
    EXPECT_EQ(banded.pixels, 8u * 5u);
    EXPECT_THROW(compare_images(a, Image(4, 4)), std::invalid_argument);
}

}  // namespace
}  // namespace lucent
