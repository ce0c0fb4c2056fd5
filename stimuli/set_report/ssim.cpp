#include "stimuli/set_report/ssim.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace lucent::stimuli {
namespace {

// Weighted local means of `values` with a separable, border-renormalised kernel.
std::vector<double> local_mean(const std::vector<double>& values, int width, int height,
                               const std::vector<double>& kernel, int radius) {
    std::vector<double> rows(values.size()), out(values.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double sum = 0.0, weight = 0.0;
            for (int k = -radius; k <= radius; ++k) {
                const int xx = x + k;
                if (xx < 0 || xx >= width) continue;
                const double w = kernel[std::size_t(k + radius)];
                sum += w * values[std::size_t(y) * width + xx];
                weight += w;
            }
            rows[std::size_t(y) * width + x] = sum / weight;
        }
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double sum = 0.0, weight = 0.0;
            for (int k = -radius; k <= radius; ++k) {
                const int yy = y + k;
                if (yy < 0 || yy >= height) continue;
                const double w = kernel[std::size_t(k + radius)];
                sum += w * rows[std::size_t(yy) * width + x];
                weight += w;
            }
            out[std::size_t(y) * width + x] = sum / weight;
        }
    return out;
}

// Eq. 13 from the five local moments.
double index(double mx, double my, double xx, double yy, double xy, double c1,
             double c2) {
    const double vx = std::max(xx - mx * mx, 0.0), vy = std::max(yy - my * my, 0.0);
    const double cov = xy - mx * my;
    return ((2 * mx * my + c1) * (2 * cov + c2)) /
           ((mx * mx + my * my + c1) * (vx + vy + c2));
}

}  // namespace

double ssim(const GreyImageView& first, const GreyImageView& second,
            std::span<const std::uint8_t> mask, const SsimOptions& options) {
    const std::size_t n =
        std::size_t(std::max(first.width, 0)) * std::max(first.height, 0);
    if (first.width != second.width || first.height != second.height ||
        first.values.size() != n || second.values.size() != n ||
        (!mask.empty() && mask.size() != n))
        throw std::invalid_argument("ssim: images of different sizes");
    if (!(options.dynamic_range > 0.0) || options.radius < 0 || !(options.sigma > 0.0))
        throw std::invalid_argument("ssim: bad options");
    const double c1 = std::pow(0.01 * options.dynamic_range, 2);
    const double c2 = std::pow(0.03 * options.dynamic_range, 2);
    auto selected = [&](std::size_t i) { return mask.empty() || mask[i] != 0; };

    const std::vector<double> x(first.values.begin(), first.values.end());
    const std::vector<double> y(second.values.begin(), second.values.end());
    if (options.global) {
        // Two passes (means, then centred moments): no cancellation in the variances.
        double sx = 0, sy = 0;
        std::size_t count = 0;
        for (std::size_t i = 0; i < n; ++i)
            if (selected(i)) sx += x[i], sy += y[i], ++count;
        if (count == 0) return 1.0;
        const double mx = sx / double(count), my = sy / double(count);
        double vx = 0, vy = 0, cov = 0;
        for (std::size_t i = 0; i < n; ++i)
            if (selected(i)) {
                vx += (x[i] - mx) * (x[i] - mx);
                vy += (y[i] - my) * (y[i] - my);
                cov += (x[i] - mx) * (y[i] - my);
            }
        vx /= double(count), vy /= double(count), cov /= double(count);
        const double value = ((2 * mx * my + c1) * (2 * cov + c2)) /
                             ((mx * mx + my * my + c1) * (vx + vy + c2));
        return std::isfinite(value) ? value : 0.0;
    }

    std::vector<double> kernel(std::size_t(2 * options.radius + 1));
    for (int k = -options.radius; k <= options.radius; ++k)
        kernel[std::size_t(k + options.radius)] =
            std::exp(-0.5 * k * k / (options.sigma * options.sigma));
    std::vector<double> xx(n), yy(n), xy(n);
    for (std::size_t i = 0; i < n; ++i)
        xx[i] = x[i] * x[i], yy[i] = y[i] * y[i], xy[i] = x[i] * y[i];
    const int w = first.width, h = first.height, r = options.radius;
    const auto mx = local_mean(x, w, h, kernel, r), my = local_mean(y, w, h, kernel, r);
    const auto mxx = local_mean(xx, w, h, kernel, r),
               myy = local_mean(yy, w, h, kernel, r);
    const auto mxy = local_mean(xy, w, h, kernel, r);
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!selected(i)) continue;
        sum += index(mx[i], my[i], mxx[i], myy[i], mxy[i], c1, c2);
        ++count;
    }
    if (count == 0) return 1.0;
    const double value = sum / double(count);
    return std::isfinite(value) ? value : 0.0;
}

}  // namespace lucent::stimuli
