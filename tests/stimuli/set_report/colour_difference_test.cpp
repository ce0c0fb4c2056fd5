// CIEDE2000 against the published test data of Sharma, Wu and Dalal (2005, Table 1),
// sRGB -> Lab against the primaries' textbook values, and the per-image summary against
// hand-computed statistics.
#include "stimuli/set_report/colour_difference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lucent::stimuli {
namespace {

struct SharmaPair {
    Lab first, second;
    double delta_e;
};

// G. Sharma, W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation
// notes, supplementary test data, and mathematical observations", Color Research and
// Application 30(1), 2005, Table 1: all 34 pairs, Delta E00 to 4 decimals.
const std::vector<SharmaPair> kSharma2005 = {
    {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
    {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
    {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
    {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
    {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
    {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
    {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
    {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
    {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
    {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
    {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
    {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
    {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
    {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
    {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
    {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
    {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
    {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
    {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
};

TEST(Ciede2000, MatchesAll34PairsOfSharmaWuDalal2005) {
    ASSERT_EQ(kSharma2005.size(), 34u);
    for (std::size_t i = 0; i < kSharma2005.size(); ++i) {
        const auto& pair = kSharma2005[i];
        SCOPED_TRACE("pair " + std::to_string(i + 1));
        // Published to 4 decimals: within rounding (5e-5) plus the formula's float error.
        EXPECT_NEAR(ciede2000(pair.first, pair.second), pair.delta_e, 1e-4);
        EXPECT_NEAR(ciede2000(pair.second, pair.first), pair.delta_e, 1e-4);
    }
    EXPECT_EQ(ciede2000({50, 10, -20}, {50, 10, -20}), 0.0);
}

TEST(Ciede2000, PureLightnessDifferenceIsDeltaLOverSL) {
    // CIEDE2000 Eq. (a = b = 0): Delta E00 = |Delta L| / S_L, S_L = 1 + 0.015 (Lbar -
    // 50)^2 / sqrt(20 + (Lbar - 50)^2).
    const double lbar = 75.0, d = (lbar - 50) * (lbar - 50);
    const double sl = 1 + 0.015 * d / std::sqrt(20 + d);
    EXPECT_NEAR(ciede2000({50, 0, 0}, {100, 0, 0}), 50.0 / sl, 1e-9);
}

TEST(SrgbToLab, PrimariesLandOnTheirD65LabValues) {
    // CIELAB (D65) of the sRGB primaries and white (IEC 61966-2-1 primaries, CIE 15
    // Lab), as tabulated e.g. by Lindbloom's calculator: to 0.05.
    const SrgbToLab to_lab;
    const struct {
        float r, g, b;
        Lab expected;
    } cases[] = {{1, 0, 0, {53.24, 80.09, 67.20}},
                 {0, 1, 0, {87.73, -86.18, 83.18}},
                 {0, 0, 1, {32.30, 79.19, -107.86}},
                 {1, 1, 1, {100.0, 0.0, 0.0}},
                 {0, 0, 0, {0.0, 0.0, 0.0}}};
    for (const auto& c : cases) {
        const Lab lab = to_lab.convert(c.r, c.g, c.b);
        SCOPED_TRACE(std::to_string(c.r) + "," + std::to_string(c.g) + "," +
                     std::to_string(c.b));
        EXPECT_NEAR(lab.L, c.expected.L, 0.05);
        EXPECT_NEAR(lab.a, c.expected.a, 0.05);
        EXPECT_NEAR(lab.b, c.expected.b, 0.05);
    }
    // Greys are achromatic, with CIE L* of the sRGB-decoded luminance.
    for (float v : {0.25f, 0.5f, 0.75f}) {
        const Lab lab = to_lab.convert(v, v, v);
        const double y = std::pow((v + 0.055) / 1.055, 2.4);
        EXPECT_NEAR(lab.L, 116.0 * std::cbrt(y) - 16.0, 0.01) << v;
        EXPECT_NEAR(lab.a, 0.0, 0.01) << v;
        EXPECT_NEAR(lab.b, 0.0, 0.01) << v;
    }
    // Out-of-range values are clamped, never NaN.
    const Lab clamped = to_lab.convert(NAN, 2.0f, -1.0f);
    EXPECT_TRUE(std::isfinite(clamped.L) && std::isfinite(clamped.a) &&
                std::isfinite(clamped.b));
}

TEST(DeltaEStatistics, MeanPercentileAndShareOverMaskedPixels) {
    // Pixels whose Delta E00 is published (pairs 1, 2, 3, 33), one masked-out pixel (17).
    std::vector<Lab> first, second;
    for (int pair : {1, 2, 3, 33, 17}) {
        first.push_back(kSharma2005[std::size_t(pair - 1)].first);
        second.push_back(kSharma2005[std::size_t(pair - 1)].second);
    }
    const std::vector<std::uint8_t> mask = {1, 1, 1, 1, 0};
    const auto stats = delta_e_statistics(first, second, mask);
    EXPECT_EQ(stats.pixels, 4u);
    EXPECT_NEAR(stats.mean, (2.0425 + 2.8615 + 3.4412 + 0.6377) / 4, 1e-4);
    EXPECT_NEAR(stats.percentile_95, 3.4412, 1e-4);  // nearest rank: the 4th of 4
    EXPECT_DOUBLE_EQ(stats.share_above_1, 0.75);
    EXPECT_NEAR(stats.max, 3.4412, 1e-4);

    const auto none = delta_e_statistics(first, second, std::vector<std::uint8_t>(5, 0));
    EXPECT_EQ(none.pixels, 0u);
    EXPECT_EQ(none.mean, 0.0);
    EXPECT_THROW(delta_e_statistics(first, second,
                                    std::span<const std::uint8_t>(mask).subspan(0, 2)),
                 std::invalid_argument);
}

}  // namespace
}  // namespace lucent::stimuli
