// SSIM against closed forms: constant images (only the luminance term is left), the
// global index of an affine pair, identity, and symmetry.
#include "stimuli/set_report/ssim.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lucent::stimuli {
namespace {

constexpr double kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;  // L = 1

TEST(Ssim, ConstantImagesLeaveOnlyTheLuminanceTerm) {
    // sigma_x = sigma_y = sigma_xy = 0 in every window: SSIM = (2ab + C1) / (a^2 + b^2 +
    // C1).
    const int w = 23, h = 17;
    const std::vector<double> a(std::size_t(w) * h, 0.3), b(std::size_t(w) * h, 0.5);
    const double expected = (2 * 0.3 * 0.5 + kC1) / (0.09 + 0.25 + kC1);
    EXPECT_NEAR(ssim({w, h, a}, {w, h, b}), expected, 1e-12);
    SsimOptions global;
    global.global = true;
    EXPECT_NEAR(ssim({w, h, a}, {w, h, b}, {}, global), expected, 1e-12);
}

TEST(Ssim, GlobalIndexOfAnAffinePair) {
    // x: half 0.2, half 0.6 (mean 0.4, variance 0.04); y = 0.5 x + 0.1 (mean 0.3,
    // variance 0.01, covariance 0.02).
    const int w = 8, h = 4;
    std::vector<double> x(std::size_t(w) * h), y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        x[i] = i % 2 ? 0.6 : 0.2;
        y[i] = 0.5 * x[i] + 0.1;
    }
    SsimOptions global;
    global.global = true;
    const double expected = (2 * 0.4 * 0.3 + kC1) * (2 * 0.02 + kC2) /
                            ((0.16 + 0.09 + kC1) * (0.04 + 0.01 + kC2));
    EXPECT_NEAR(ssim({w, h, x}, {w, h, y}, {}, global), expected, 1e-12);
}

TEST(Ssim, IdenticalImagesGiveOneAndTheIndexIsSymmetric) {
    const int w = 40, h = 30;
    std::vector<double> x(std::size_t(w) * h), y(x.size());
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            x[std::size_t(j) * w + i] = 0.5 + 0.4 * std::sin(0.3 * i) * std::cos(0.2 * j);
            y[std::size_t(j) * w + i] =
                0.5 + 0.4 * std::sin(0.3 * i + 0.5) * std::cos(0.2 * j);
        }
    EXPECT_NEAR(ssim({w, h, x}, {w, h, x}), 1.0, 1e-12);
    const double s = ssim({w, h, x}, {w, h, y});
    EXPECT_LT(s, 0.99);
    EXPECT_GT(s, -1.0);
    EXPECT_NEAR(ssim({w, h, y}, {w, h, x}), s, 1e-12);
    // A mask selects whose windows are averaged; none selected gives 1 by definition.
    const std::vector<std::uint8_t> none(x.size(), 0);
    EXPECT_EQ(ssim({w, h, x}, {w, h, y}, none), 1.0);
    EXPECT_THROW(ssim({w, h, x}, {w - 1, h, y}), std::invalid_argument);
}

}  // namespace
}  // namespace lucent::stimuli
