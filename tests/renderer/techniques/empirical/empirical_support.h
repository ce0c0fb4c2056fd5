#pragma once
// Scenes and image comparisons shared by the empirical technique's tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "renderer/core/image_compare.h"
#include "renderer/core/technique.h"
#include "renderer/techniques/registry.h"

namespace lucent::test {

inline std::shared_ptr<const Mesh> builtin_mesh(const std::string& spec) {
    static std::map<std::string, std::shared_ptr<const Mesh>> cache;
    auto& mesh = cache[spec];
    if (!mesh) mesh = std::make_shared<const Mesh>(load_mesh(spec));
    return mesh;
}

inline Scene empirical_scene(std::shared_ptr<const Mesh> mesh,
                             std::vector<KnobAssignment> settings, int width, int height,
                             glm::vec3 view_direction = {0, 0, 1}) {
    const Technique& technique = find_technique("empirical");
    return make_scene(std::move(mesh), technique,
                      resolve_knob_values(knobs_for(technique), settings), width, height,
                      view_direction);
}

// Settings under which the image is the backlight term alone with wb = 1, r = 1 and
// Kd + Kb = 1: every covered pixel shows 1 - t, t the thickness (Eq. 3.10).
inline std::vector<KnobAssignment> thickness_only(
    std::vector<KnobAssignment> extra = {}) {
    std::vector<KnobAssignment> s = {{"albedo", "0"},
                                     {"ambient", "0"},
                                     {"diffuse_contribution", "0"},
                                     {"specular_contribution", "0"},
                                     {"backlight", "1"},
                                     {"diffuse_weight", "1"},
                                     {"thickness_exponent", "1"},
                                     {"blur_kernel", "1"}};
    s.insert(s.end(), extra.begin(), extra.end());
    return s;
}

inline double max_abs_difference(const Image& a, const Image& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i)
        m = std::max(m, std::abs(double(a.rgba[i]) - double(b.rgba[i])));
    return m;
}

inline bool all_finite(const Image& image) {
    return std::all_of(image.rgba.begin(), image.rgba.end(),
                       [](float v) { return std::isfinite(v); });
}

}  // namespace lucent::test
