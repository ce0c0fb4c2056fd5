#include "renderer/techniques/ward/ward_brdf.h"

#include <algorithm>
#include <cmath>

namespace lucent::ward {

float ward_specular(glm::vec3 n, glm::vec3 l, glm::vec3 v, float rho_s, float alpha) {
    const float cos_i = glm::dot(n, l);
    const float cos_o = glm::dot(n, v);
    if (cos_i <= 0.0f || cos_o <= 0.0f || rho_s <= 0.0f) return 0.0f;

    // Half vector and tan^2(delta) = (1 - cos^2) / cos^2, computed without acos.
    const glm::vec3 sum = l + v;
    const float length = glm::length(sum);
    if (!(length > 0.0f))
        return 0.0f;  // l = -v cannot happen with both above the surface
    const float cos_delta = glm::dot(n, sum / length);
    if (cos_delta <= 0.0f) return 0.0f;
    const float cos2 = cos_delta * cos_delta;
    const float tan2 = std::max(1.0f - cos2, 0.0f) / cos2;

    // Ward's normalisation (Eq. 13 with alpha^2), guarded for alpha -> 0 and grazing
    // angles.
    const float a = std::max(alpha, kMinRoughness);
    const float a2 = a * a;
    const float cosine_product = std::max(cos_i * cos_o, kMinCosineProduct);
    return rho_s * std::exp(-tan2 / a2) / (4.0f * kPi * a2 * std::sqrt(cosine_product));
}

float ward_brdf(glm::vec3 n, glm::vec3 l, glm::vec3 v, float rho_d, float rho_s,
                float alpha) {
    if (glm::dot(n, l) <= 0.0f || glm::dot(n, v) <= 0.0f) return 0.0f;
    return rho_d / kPi + ward_specular(n, l, v, rho_s, alpha);
}

}  // namespace lucent::ward
