#pragma once
// Ward's isotropic BRDF (Ward 1992, Eq. 4; Domon et al. Eq. 13), GL-free, shared by the
// `ward` and `contrast_reversed` CPU references. The GLSL in shaders/ward_brdf.glsl
// evaluates the same expressions with the same guards.
//
//   f(l, v) = rho_d / pi + rho_s * exp(-tan^2(delta) / alpha^2)
//                                  / (4 pi alpha^2 sqrt(cos(theta_i) cos(theta_o)))
//
// delta is the angle between the normal and the half vector. Ward's original has alpha^2
// in the denominator; Domon et al. print alpha, which is not normalised.
#include <glm/glm.hpp>

namespace lucent::ward {

// Guards (also in the shader): alpha is raised to kMinRoughness so the lobe stays finite;
// cos(theta_i) cos(theta_o) is raised to kMinCosineProduct so the specular term stays
// finite at grazing angles (it is 0 below the horizon on either side).
inline constexpr float kMinRoughness = 1e-3f;
inline constexpr float kMinCosineProduct = 1e-4f;
inline constexpr float kPi = 3.14159265358979323846f;

// The specular lobe f_s (1/sr), without the diffuse part. n, l, v: unit vectors, l and v
// pointing away from the surface. Returns 0 when l or v is below the surface.
float ward_specular(glm::vec3 n, glm::vec3 l, glm::vec3 v, float rho_s, float alpha);

// The whole BRDF f = rho_d / pi + f_s (1/sr); 0 below the surface.
float ward_brdf(glm::vec3 n, glm::vec3 l, glm::vec3 v, float rho_d, float rho_s,
                float alpha);

}  // namespace lucent::ward
