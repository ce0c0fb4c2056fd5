#include "stimuli/set_report/colour_difference.h"

#include <lcms2.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lucent::stimuli {

struct SrgbToLab::Handles {
    cmsHPROFILE srgb = nullptr, xyz = nullptr;
    cmsHTRANSFORM transform = nullptr;
    cmsCIEXYZ d65{};
    ~Handles() {
        if (transform) cmsDeleteTransform(transform);
        if (xyz) cmsCloseProfile(xyz);
        if (srgb) cmsCloseProfile(srgb);
    }
};

SrgbToLab::SrgbToLab() : handles_(std::make_unique<Handles>()) {
    // sRGB -> XYZ in the ICC connection space (D50-adapted), adapted back to D65 (the
    // white of sRGB, Bradford as littleCMS adapted it), then Lab relative to D65: the
    // primaries land on their textbook Lab values and white on L = 100, a = b = 0.
    cmsCIExyY white;
    cmsWhitePointFromTemp(&white, 6504);
    cmsxyY2XYZ(&handles_->d65, &white);
    handles_->srgb = cmsCreate_sRGBProfile();
    handles_->xyz = cmsCreateXYZProfile();
    if (handles_->srgb && handles_->xyz)
        handles_->transform =
            cmsCreateTransform(handles_->srgb, TYPE_RGB_FLT, handles_->xyz, TYPE_XYZ_DBL,
                               INTENT_RELATIVE_COLORIMETRIC, cmsFLAGS_NOCACHE);
    if (!handles_->transform)
        throw std::runtime_error("littleCMS: cannot create the sRGB -> XYZ transform");
}

SrgbToLab::~SrgbToLab() = default;

Lab SrgbToLab::convert(float r, float g, float b) const {
    const float rgb[3] = {r, g, b};
    return convert(rgb).front();
}

std::vector<Lab> SrgbToLab::convert(std::span<const float> rgb) const {
    if (rgb.size() % 3 != 0)
        throw std::invalid_argument("SrgbToLab: values are not RGB triples");
    std::vector<float> clamped(rgb.begin(), rgb.end());
    for (float& v : clamped) v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    const std::size_t pixels = clamped.size() / 3;
    std::vector<cmsCIEXYZ> xyz(pixels);
    // cmsDoTransform takes a 32-bit count: convert in chunks.
    constexpr std::size_t kChunk = 1 << 20;
    for (std::size_t start = 0; start < pixels; start += kChunk) {
        const std::size_t n = std::min(kChunk, pixels - start);
        cmsDoTransform(handles_->transform, clamped.data() + start * 3,
                       xyz.data() + start, cmsUInt32Number(n));
    }
    std::vector<Lab> out(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        cmsCIEXYZ adapted;
        cmsCIELab lab;
        cmsAdaptToIlluminant(&adapted, cmsD50_XYZ(), &handles_->d65, &xyz[i]);
        cmsXYZ2Lab(&handles_->d65, &lab, &adapted);
        out[i] = {lab.L, lab.a, lab.b};
    }
    return out;
}

double ciede2000(const Lab& first, const Lab& second) {
    const cmsCIELab a{first.L, first.a, first.b}, b{second.L, second.a, second.b};
    const double difference = cmsCIE2000DeltaE(&a, &b, 1.0, 1.0, 1.0);
    return std::isfinite(difference) ? difference : 0.0;
}

DeltaEStatistics delta_e_statistics(std::span<const Lab> first,
                                    std::span<const Lab> second,
                                    std::span<const std::uint8_t> mask) {
    if (first.size() != second.size() || first.size() != mask.size())
        throw std::invalid_argument("delta_e_statistics: images of different sizes");
    std::vector<double> differences;
    for (std::size_t i = 0; i < mask.size(); ++i)
        if (mask[i]) differences.push_back(ciede2000(first[i], second[i]));
    DeltaEStatistics stats;
    stats.pixels = differences.size();
    if (differences.empty()) return stats;
    double sum = 0.0, squares = 0.0;
    std::size_t above = 0;
    for (double d : differences) {
        sum += d;
        squares += d * d;
        above += d > 1.0;
    }
    stats.mean = sum / double(differences.size());
    stats.root_mean_square = std::sqrt(squares / double(differences.size()));
    stats.share_above_1 = double(above) / double(differences.size());
    // Nearest rank: the smallest value with at least 95% of the pixels at or below it.
    const std::size_t rank = std::size_t(std::ceil(0.95 * double(differences.size())));
    std::nth_element(differences.begin(), differences.begin() + (rank - 1),
                     differences.end());
    stats.percentile_95 = differences[rank - 1];
    stats.max = *std::max_element(differences.begin(), differences.end());
    return stats;
}

}  // namespace lucent::stimuli
