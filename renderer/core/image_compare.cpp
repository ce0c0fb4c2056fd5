#include "renderer/core/image_compare.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lucent {

ImageErrorStats compare_images(const Image& a, const Image& b, int band) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("compare_images: sizes differ");
    const auto covered = [](const Image& image, int x, int y) {
        return image.at(x, y).a > 0.5f;
    };
    const auto near_silhouette = [&](int x, int y) {
        if (covered(a, x, y) != covered(b, x, y)) return true;
        for (int j = -band; j <= band; ++j)
            for (int i = -band; i <= band; ++i) {
                const int sx = std::clamp(x + i, 0, a.width - 1),
                          sy = std::clamp(y + j, 0, a.height - 1);
                if (covered(a, sx, sy) != covered(a, x, y) ||
                    covered(b, sx, sy) != covered(b, x, y))
                    return true;
            }
        return false;
    };
    std::vector<double> worst;
    double sum = 0.0, sum_squares = 0.0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            if (band > 0 && near_silhouette(x, y)) continue;
            double pixel_worst = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double d = std::abs(double(a.at(x, y)[c]) - double(b.at(x, y)[c]));
                // A non-finite difference counts as the largest possible error.
                const double diff = std::isfinite(d) ? d : 1e30;
                sum += diff;
                sum_squares += diff * diff;
                pixel_worst = std::max(pixel_worst, diff);
            }
            worst.push_back(pixel_worst);
        }
    ImageErrorStats stats;
    stats.pixels = worst.size();
    if (worst.empty()) return stats;
    const double n = 3.0 * static_cast<double>(worst.size());
    stats.mean = sum / n;
    stats.rmse = std::sqrt(sum_squares / n);
    std::sort(worst.begin(), worst.end());
    stats.p99 =
        worst[std::min(worst.size() - 1, static_cast<std::size_t>(0.99 * worst.size()))];
    stats.max = worst.back();
    return stats;
}

ReferenceError reference_error(const Image& coarse, const Image& fine) {
    double sum2 = 0.0, ref2 = 0.0, worst = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < fine.height; ++y)
        for (int x = 0; x < fine.width; ++x) {
            const glm::vec4 a = coarse.at(x, y), b = fine.at(x, y);
            if (a.a == 0.0f || b.a == 0.0f) continue;
            for (int c = 0; c < 3; ++c) {
                const double d = double(a[c]) - double(b[c]);
                sum2 += d * d;
                ref2 += double(b[c]) * double(b[c]);
                worst = std::max(worst, std::abs(d));
            }
            ++count;
        }
    ReferenceError error;
    if (count > 0) {
        error.rms = std::sqrt(sum2 / (3.0 * count));
        error.max = worst;
        error.relative_rms = ref2 > 0.0 ? std::sqrt(sum2 / ref2) : 0.0;
    }
    return error;
}

}  // namespace lucent
