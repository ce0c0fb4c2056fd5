// Image output: formats, encodings, atomic writes, and no NaN/Inf ever written.
#include "renderer/core/image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "common/srgb.h"
#include "renderer/core/display_transform.h"
#include "renderer/core/image_compare.h"
#include "tests/support/test_paths.h"

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

// The final colour pass's table gives exactly the codes of the formula,
// lround(srgb_encode(v) * 255): at
// every code transition (found here by scanning the formula), over random values, and
// for out-of-range and non-finite input.
TEST(ImageIo, EightBitSrgbTableMatchesTheFormulaEverywhere) {
    const auto formula = [](float v) {
        return int(std::lround(common::srgb_encode(v) * 255.0f));
    };
    // Transitions by stepping through the codes' preimages with nextafter near each
    // analytic crossing: sRGB^-1((k - 0.5) / 255).
    for (int k = 1; k <= 255; ++k) {
        const double s = (k - 0.5) / 255.0;
        const double x = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
        float v = static_cast<float>(x);
        for (int step = 0; step < 2000; ++step) v = std::nextafter(v, 0.0f);
        ASSERT_LT(formula(v), k);  // the scan below crosses the transition to k
        for (int step = 0; step < 4000; ++step, v = std::nextafter(v, 2.0f))
            ASSERT_EQ(display_code(v), formula(v)) << "v = " << v << ", code " << k;
        ASSERT_GE(formula(v), k);
    }
    std::mt19937 engine(17);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int i = 0; i < 1'000'000; ++i) {
        const float v = unit(engine);
        ASSERT_EQ(display_code(v), formula(v)) << "v = " << v;
    }
    // Denormals and exact ends.
    for (float v : {0.0f, -0.0f, std::numeric_limits<float>::denorm_min(),
                    std::numeric_limits<float>::min(), 1.0f, std::nextafter(1.0f, 0.0f)})
        EXPECT_EQ(display_code(v), formula(v)) << v;
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(display_code(-0.5f), 0);
    EXPECT_EQ(display_code(7.0f), 255);
    EXPECT_EQ(display_code(inf), 255);
    EXPECT_EQ(display_code(-inf), 0);
    EXPECT_EQ(display_code(std::nanf("")), 0);
}

// The final colour pass's value for 16-bit files and reports: clamped (NaN and -Inf as
// black, +Inf as white), then the IEC 61966-2-1 curve.
TEST(DisplayTransform, ValuesAreClampedThenEncodedAndNeverNaN) {
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(display_value(std::nanf("")), 0.0f);
    EXPECT_EQ(display_value(-inf), 0.0f);
    EXPECT_FLOAT_EQ(display_value(inf), 1.0f);
    EXPECT_FLOAT_EQ(display_value(7.0f), 1.0f);
    EXPECT_EQ(display_value(-0.25f), 0.0f);
    EXPECT_NEAR(display_value(0.5f), 0.735356983f, 1e-6f);
    EXPECT_NEAR(display_value(0.001f), 0.01292f, 1e-7f);  // the linear segment
}

// PNG is lossless with either encoding: every pixel of a noisy image (no runs for the
// encoder to exploit) reads back as the formula's 8-bit code, and writing it again gives
// the same bytes.
TEST(ImageIo, PngStoresTheEightBitCodesLosslesslyAndDeterministically) {
    const auto dir = test::scratch_dir("image_png_lossless");
    Image image(67, 45);  // odd sizes: no row or filter alignment to lean on
    std::mt19937 engine(3);
    std::uniform_real_distribution<float> value(-0.1f, 1.1f);
    for (float& v : image.rgba) v = value(engine);
    const auto bytes = [](const std::filesystem::path& path) {
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    for (const PngEncoding png : {PngEncoding::fast, PngEncoding::compact}) {
        write_image(dir / "a.png", image, {.png = png});
        write_image(dir / "b.png", image, {.png = png});
        EXPECT_EQ(bytes(dir / "a.png"), bytes(dir / "b.png"));
        const Image back = read_image(dir / "a.png");
        ASSERT_EQ(back.width, image.width);
        ASSERT_EQ(back.height, image.height);
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                for (int c = 0; c < 3; ++c) {
                    const float v = std::clamp(image.at(x, y)[c], 0.0f, 1.0f);
                    const long code = std::lround(common::srgb_encode(v) * 255.0f);
                    ASSERT_EQ(std::lround(back.at(x, y)[c] * 255.0f), code)
                        << x << "," << y << " channel " << c << ", encoding " << int(png);
                }
    }
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
