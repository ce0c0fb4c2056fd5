#pragma once
// Structural similarity (Wang, Bovik, Sheikh and Simoncelli 2004, Eq. 13) of two
// single-channel images, e.g. the luminance of two stimuli: local means, variances and
// covariance under an 11x11 Gaussian window (sigma 1.5), C1 = (0.01 L)^2 and
// C2 = (0.03 L)^2 for a dynamic range L, averaged over the masked pixels.
#include <cstdint>
#include <span>

namespace lucent::stimuli {

struct SsimOptions {
    // Gaussian window: the paper's 11x11, sigma 1.5. Near the border the window is cut
    // off and its weights renormalised, so a constant image keeps its local mean.
    double sigma = 1.5;
    int radius = 5;
    // One window over the whole image instead (the global form of the index).
    bool global = false;
    double dynamic_range = 1.0;  // L: values span [0, L]
};

struct GreyImageView {
    int width = 0;
    int height = 0;
    std::span<const double> values;  // width * height, row-major
};

// Mean SSIM over the pixels where `mask` is non-zero (an empty mask means every pixel);
// 1 when no pixel is selected. Throws std::invalid_argument for mismatched sizes.
double ssim(const GreyImageView& first, const GreyImageView& second,
            std::span<const std::uint8_t> mask = {}, const SsimOptions& options = {});

}  // namespace lucent::stimuli
