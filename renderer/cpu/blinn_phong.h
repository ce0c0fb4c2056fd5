#pragma once
// Blinn-Phong's specular lobe, as every CPU reference evaluates it (the GPU's twin is
// techniques/shaders/blinn_phong.glsl, the same operations in float): the empirical
// technique's specular term (thesis Eq. 3.9), and the dipole's and the htsm's surface
// specular.
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

namespace lucent {

// max(N.H, 0)^shininess for a unit normal `n` and a unit direction `l` towards the
// light, both in eye space, with the viewer at infinity along +z as OpenGL's
// fixed-function half vector: H = normalize(L + (0, 0, 1)), and N.H = 0 where L points
// straight away from the viewer. Shininess 0 is a constant lobe (0^0 = 1); a
// non-positive N.H otherwise gives 0 (pow is undefined there in GLSL). Callers apply
// their own N.L > 0 (and shadow) test.
inline double blinn_phong_lobe(glm::dvec3 n, glm::dvec3 l, double shininess) {
    const glm::dvec3 half_sum = l + glm::dvec3(0.0, 0.0, 1.0);
    const double length2 = glm::dot(half_sum, half_sum);
    const double n_dot_h =
        length2 > 1e-30 ? std::max(glm::dot(n, half_sum / std::sqrt(length2)), 0.0) : 0.0;
    if (shininess == 0.0) return 1.0;
    return n_dot_h <= 0.0 ? 0.0 : std::pow(n_dot_h, shininess);
}

}  // namespace lucent
