// RayCaster: the checks and layer stepping every backend shares, over the installed
// backend's queries (core/cpu_backend.h; Embree in every program that renders).
#include "renderer/cpu/ray_caster.h"

#include <cmath>
#include <limits>

#include "renderer/core/cpu_backend.h"

namespace lucent {
namespace {

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Unit direction, or nullopt when the ray is unusable.
std::optional<glm::vec3> unit(glm::vec3 origin, glm::vec3 direction) {
    const float length = glm::length(direction);
    if (!finite(origin) || !(length > 0.0f) || !std::isfinite(length))
        return std::nullopt;
    return direction / length;
}

}  // namespace

RayCaster::RayCaster(const Mesh& mesh)
    : queries_(cpu_backend().ray_queries(mesh)),
      epsilon_(1e-5f * std::max(mesh.bounding_sphere().radius, 1e-6f)) {}

RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

float RayCaster::layer_epsilon() const { return epsilon_; }

std::optional<RayHit> RayCaster::first_hit(glm::vec3 origin, glm::vec3 direction,
                                           float t_min, float t_max) const {
    const std::optional<glm::vec3> dir = unit(origin, direction);
    if (!dir || !(t_max > t_min)) return std::nullopt;
    return queries_->first_hit(origin, *dir, t_min, t_max);
}

std::vector<RayHit> RayCaster::hits(glm::vec3 origin, glm::vec3 direction,
                                    int max_hits) const {
    std::vector<RayHit> layers;
    float t_min = 0.0f;
    while (static_cast<int>(layers.size()) < max_hits) {
        const std::optional<RayHit> hit = first_hit(origin, direction, t_min);
        if (!hit) break;
        layers.push_back(*hit);
        // Relative term too: far from the origin a float step can exceed the epsilon.
        t_min = hit->distance + epsilon_ +
                4.0f * std::numeric_limits<float>::epsilon() * hit->distance;
    }
    return layers;
}

bool RayCaster::occluded(glm::vec3 origin, glm::vec3 direction, float t_min,
                         float t_max) const {
    const std::optional<glm::vec3> dir = unit(origin, direction);
    if (!dir || !(t_max > t_min)) return false;
    return queries_->occluded(origin, *dir, t_min, t_max);
}

}  // namespace lucent
