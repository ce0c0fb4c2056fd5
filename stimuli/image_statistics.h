#pragma once
// Image statistics over an object's pixels (Motoyoshi 2010; Domon et al. Sec. 6): the
// luminance histogram, mean, RMS contrast, skewness and the correlation between
// saturation and intensity. Background pixels (alpha or mask zero) are left out.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace lucent::stimuli {

// Rec. 709 / sRGB-primaries luminance of *linear* RGB values.
double luminance_rec709(double r, double g, double b);

struct ImageStatistics {
    std::size_t object_pixels = 0;  // pixels counted (mask set)
    double mean_luminance = 0.0;    // mean of Rec. 709 luminance, linear
    double sd_luminance = 0.0;      // population SD (divides by N)
    double rms_contrast = 0.0;      // sd / mean; 0 when mean <= 0 or no pixels
    double skewness = 0.0;          // m3 / m2^1.5; 0 when sd == 0
    double saturation_intensity_correlation = 0.0;  // Pearson r; 0 when a variance is 0
    // Luminance histogram: bins of equal width over [0, 1]; values >= 1 fall into the
    // last bin, values < 0 into the first.
    std::vector<std::uint64_t> luminance_histogram;
};

// A view of a linear float image, row-major, `channels` (3 or 4) values per pixel.
struct FloatImageView {
    int width = 0;
    int height = 0;
    int channels = 4;
    std::span<const float> values;
};

// Object pixels are those whose alpha (channel 4) exceeds 0.5; with 3 channels every
// pixel counts. Throws std::invalid_argument for a view whose size does not match.
ImageStatistics compute_image_statistics(const FloatImageView& image,
                                         int histogram_bins = 16);

// Same, with an explicit mask (non-zero = object), one byte per pixel.
ImageStatistics compute_image_statistics(const FloatImageView& image,
                                         std::span<const std::uint8_t> mask,
                                         int histogram_bins = 16);

}  // namespace lucent::stimuli
