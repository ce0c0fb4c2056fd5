#pragma once
// Perceptual colour differences between two displayed images (sRGB as shown on screen):
// each pixel to CIELAB through littleCMS (its built-in sRGB profile to XYZ, adapted to
// D65 with littleCMS's Bradford transform, Lab relative to D65), CIEDE2000 per pixel
// (littleCMS's cmsCIE2000DeltaE, kL = kC = kH = 1), summarised over the object's pixels.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace lucent::stimuli {

struct Lab {
    double L = 0.0, a = 0.0, b = 0.0;
};

// CIEDE2000 (Sharma, Wu and Dalal 2005) with unit weights.
double ciede2000(const Lab& first, const Lab& second);

// sRGB-encoded values in [0, 1] (what a PNG stores), 3 per pixel, to Lab. Owns the
// littleCMS profiles and transform; not copyable.
class SrgbToLab {
public:
    SrgbToLab();
    ~SrgbToLab();
    SrgbToLab(const SrgbToLab&) = delete;
    SrgbToLab& operator=(const SrgbToLab&) = delete;

    Lab convert(float r, float g, float b) const;
    // `rgb` holds 3 values per pixel; values outside [0, 1] are clamped first.
    std::vector<Lab> convert(std::span<const float> rgb) const;

private:
    struct Handles;
    std::unique_ptr<Handles> handles_;
};

// Delta E00 over the pixels where `mask` is non-zero (both images the same size).
struct DeltaEStatistics {
    std::size_t pixels = 0;         // pixels compared
    double mean = 0.0;              // mean Delta E00 (0 without pixels)
    double root_mean_square = 0.0;  // sqrt of the mean squared Delta E00
    double percentile_95 = 0.0;     // nearest-rank 95th percentile
    double share_above_1 = 0.0;     // fraction of pixels with Delta E00 > 1
    double max = 0.0;
};
// Throws std::invalid_argument when the sizes disagree.
DeltaEStatistics delta_e_statistics(std::span<const Lab> first,
                                    std::span<const Lab> second,
                                    std::span<const std::uint8_t> mask);

}  // namespace lucent::stimuli
