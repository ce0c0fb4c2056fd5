#include "stimuli/image_statistics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lucent::stimuli {
namespace {

// Intensity and saturation of the HSI model: I = (R+G+B)/3, S = 1 - min(R,G,B)/I
// (S = 0 for black). Negative channel values are treated as 0.
struct SaturationIntensity {
    double saturation;
    double intensity;
};

SaturationIntensity hsi(double r, double g, double b) {
    r = std::max(r, 0.0);
    g = std::max(g, 0.0);
    b = std::max(b, 0.0);
    const double intensity = (r + g + b) / 3.0;
    if (intensity <= 0.0) return {0.0, 0.0};
    return {1.0 - std::min({r, g, b}) / intensity, intensity};
}

// Pearson correlation from centred sums; 0 when either variable is constant.
double pearson(double sxy, double sxx, double syy) {
    const double denominator = std::sqrt(sxx * syy);
    if (!(denominator > 0.0) || !std::isfinite(denominator)) return 0.0;
    return std::clamp(sxy / denominator, -1.0, 1.0);
}

}  // namespace

double luminance_rec709(double r, double g, double b) {
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
}

ImageStatistics compute_image_statistics(const FloatImageView& image,
                                         std::span<const std::uint8_t> mask,
                                         int histogram_bins) {
    if (image.width < 0 || image.height < 0 ||
        (image.channels != 3 && image.channels != 4))
        throw std::invalid_argument("image statistics: need a 3- or 4-channel image");
    const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
    if (image.values.size() != pixels * std::size_t(image.channels))
        throw std::invalid_argument(
            "image statistics: " + std::to_string(image.values.size()) +
            " values for a " + std::to_string(image.width) + "x" +
            std::to_string(image.height) + " image");
    if (mask.size() != pixels)
        throw std::invalid_argument("image statistics: mask size differs from the image");
    histogram_bins = std::max(histogram_bins, 1);

    ImageStatistics stats;
    stats.luminance_histogram.assign(std::size_t(histogram_bins), 0);
    auto rgb = [&](std::size_t i, int c) {
        return double(image.values[i * image.channels + c]);
    };
    auto finite_pixel = [&](std::size_t i) {
        return std::isfinite(rgb(i, 0)) && std::isfinite(rgb(i, 1)) &&
               std::isfinite(rgb(i, 2));
    };

    // Pass 1: counts, means and the histogram (non-finite pixels are not object pixels).
    double sum_y = 0.0, sum_s = 0.0, sum_i = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
        if (!mask[p] || !finite_pixel(p)) continue;
        const double y = luminance_rec709(rgb(p, 0), rgb(p, 1), rgb(p, 2));
        const auto si = hsi(rgb(p, 0), rgb(p, 1), rgb(p, 2));
        ++stats.object_pixels;
        sum_y += y;
        sum_s += si.saturation;
        sum_i += si.intensity;
        const double scaled = std::clamp(y, 0.0, 1.0) * histogram_bins;
        const auto bin =
            std::min<std::size_t>(std::size_t(scaled), std::size_t(histogram_bins - 1));
        ++stats.luminance_histogram[bin];
    }
    if (stats.object_pixels == 0) return stats;
    const double n = double(stats.object_pixels);
    const double mean_y = sum_y / n, mean_s = sum_s / n, mean_i = sum_i / n;

    // Pass 2: centred moments (two passes keep the variance accurate for bright images).
    double m2 = 0.0, m3 = 0.0, sss = 0.0, sii = 0.0, ssi = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
        if (!mask[p] || !finite_pixel(p)) continue;
        const double dy = luminance_rec709(rgb(p, 0), rgb(p, 1), rgb(p, 2)) - mean_y;
        const auto si = hsi(rgb(p, 0), rgb(p, 1), rgb(p, 2));
        const double ds = si.saturation - mean_s, di = si.intensity - mean_i;
        m2 += dy * dy;
        m3 += dy * dy * dy;
        sss += ds * ds;
        sii += di * di;
        ssi += ds * di;
    }
    m2 /= n;
    m3 /= n;
    stats.mean_luminance = mean_y;
    stats.sd_luminance = std::sqrt(m2);
    // A relative tolerance keeps rounding noise of a constant image from reading as
    // spread.
    const double noise_floor = 1e-12 * std::max(1.0, mean_y * mean_y);
    if (m2 <= noise_floor) stats.sd_luminance = 0.0;
    stats.rms_contrast = mean_y > 0.0 ? stats.sd_luminance / mean_y : 0.0;
    stats.skewness = stats.sd_luminance > 0.0 ? m3 / std::pow(m2, 1.5) : 0.0;
    stats.saturation_intensity_correlation = pearson(ssi, sss, sii);
    return stats;
}

ImageStatistics compute_image_statistics(const FloatImageView& image,
                                         int histogram_bins) {
    const std::size_t pixels =
        std::size_t(std::max(image.width, 0)) * std::size_t(std::max(image.height, 0));
    std::vector<std::uint8_t> mask(pixels, 1);
    if (image.channels == 4 && image.values.size() == pixels * 4)
        for (std::size_t p = 0; p < pixels; ++p) mask[p] = image.values[p * 4 + 3] > 0.5f;
    return compute_image_statistics(image, mask, histogram_bins);
}

}  // namespace lucent::stimuli
