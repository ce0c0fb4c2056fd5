#pragma once
// Scenes and image comparisons shared by the empirical technique's tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "core/technique.h"
#include "techniques/registry.h"

namespace lucent::test {

inline std::shared_ptr<const Mesh> builtin_mesh(const std::string& spec) {
    static std::map<std::string, std::shared_ptr<const Mesh>> cache;
    auto& mesh = cache[spec];
    if (!mesh) mesh = std::make_shared<const Mesh>(load_mesh(spec));
    return mesh;
}

inline Scene empirical_scene(std::shared_ptr<const Mesh> mesh, std::vector<KnobAssignment> settings,
                             int width, int height, glm::vec3 view_direction = {0, 0, 1}) {
    const Technique& technique = find_technique("empirical");
    return make_scene(std::move(mesh), technique, resolve_knob_values(knobs_for(technique), settings),
                      width, height, view_direction);
}

// Settings under which the image is the backlight term alone with wb = 1, r = 1 and
// Kd + Kb = 1: every covered pixel shows 1 - t, t the thickness (Eq. 3.10).
inline std::vector<KnobAssignment> thickness_only(std::vector<KnobAssignment> extra = {}) {
    std::vector<KnobAssignment> s = {{"albedo", "0"},       {"ambient", "0"},
                                     {"diffuse_contribution", "0"}, {"specular_contribution", "0"},
                                     {"backlight", "1"},    {"diffuse_weight", "1"},
                                     {"thickness_exponent", "1"}, {"blur_kernel", "1"}};
    s.insert(s.end(), extra.begin(), extra.end());
    return s;
}

struct ImageDifference {
    double mean = 0.0;  // mean absolute difference over compared channel values
    double p99 = 0.0;   // 99th percentile of per-pixel max channel difference
    double max = 0.0;
    std::size_t pixels = 0;  // pixels compared
};

// Compares rgb outside a 1-pixel band around the silhouette of either image (pixels with
// a neighbour of different coverage), where rasterisation and ray casting may disagree.
inline ImageDifference compare_outside_silhouettes(const Image& a, const Image& b) {
    const auto covered = [](const Image& image, int x, int y) { return image.at(x, y).a > 0.5f; };
    std::vector<double> per_pixel;
    double sum = 0.0;
    ImageDifference d;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            bool band = false;
            for (int j = -1; j <= 1 && !band; ++j)
                for (int i = -1; i <= 1 && !band; ++i) {
                    const int sx = std::clamp(x + i, 0, a.width - 1), sy = std::clamp(y + j, 0, a.height - 1);
                    band = covered(a, sx, sy) != covered(a, x, y) || covered(b, sx, sy) != covered(b, x, y) ||
                           covered(a, x, y) != covered(b, x, y);
                }
            if (band) continue;
            double worst = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double diff = std::abs(double(a.at(x, y)[c]) - double(b.at(x, y)[c]));
                sum += diff;
                worst = std::max(worst, diff);
            }
            per_pixel.push_back(worst);
        }
    d.pixels = per_pixel.size();
    if (per_pixel.empty()) return d;
    d.mean = sum / (3.0 * per_pixel.size());
    std::sort(per_pixel.begin(), per_pixel.end());
    d.p99 = per_pixel[std::min(per_pixel.size() - 1, static_cast<std::size_t>(0.99 * per_pixel.size()))];
    d.max = per_pixel.back();
    return d;
}

inline double max_abs_difference(const Image& a, const Image& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i)
        m = std::max(m, std::abs(double(a.rgba[i]) - double(b.rgba[i])));
    return m;
}

inline bool all_finite(const Image& image) {
    return std::all_of(image.rgba.begin(), image.rgba.end(), [](float v) { return std::isfinite(v); });
}

}  // namespace lucent::test
