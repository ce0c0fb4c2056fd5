// RayCaster on Embree 3: one device and one static, robust triangle scene per mesh.
#include "renderer/cpu/ray_caster.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "renderer/cpu/embree_support.h"

namespace lucent {

struct RayCaster::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<glm::vec3> positions;  // copies: hit normals are computed from them
    std::vector<glm::uvec3> triangles;
    float epsilon = 0.0f;

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

namespace {

using embree::finite;

RTCRayHit make_ray(glm::vec3 origin, glm::vec3 unit_direction, float t_min, float t_max) {
    RTCRayHit query{};
    query.ray = embree::make_ray(origin, unit_direction, t_min, t_max);
    query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    query.hit.primID = RTC_INVALID_GEOMETRY_ID;
    return query;
}

// Embree's tnear is inclusive; the queries here exclude t_min itself.
float exclusive_near(float t_min) {
    return std::nextafter(std::max(t_min, 0.0f), std::numeric_limits<float>::infinity());
}

// Unit direction, or nullopt when the ray is unusable.
std::optional<glm::vec3> unit(glm::vec3 origin, glm::vec3 direction) {
    const float length = glm::length(direction);
    if (!finite(origin) || !(length > 0.0f) || !std::isfinite(length))
        return std::nullopt;
    return direction / length;
}

}  // namespace

RayCaster::RayCaster(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
    embree::check_indices(mesh);
    impl_->positions = mesh.positions;
    impl_->triangles = mesh.triangles;
    impl_->epsilon = 1e-5f * std::max(mesh.bounding_sphere().radius, 1e-6f);
    impl_->device = embree::new_device();
    impl_->scene = embree::build_scene(impl_->device, mesh);
}

RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

float RayCaster::layer_epsilon() const { return impl_->epsilon; }

std::optional<RayHit> RayCaster::first_hit(glm::vec3 origin, glm::vec3 direction,
                                           float t_min, float t_max) const {
    const std::optional<glm::vec3> dir = unit(origin, direction);
    if (!dir || !(t_max > t_min)) return std::nullopt;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit query = make_ray(origin, *dir, exclusive_near(t_min), t_max);
    rtcIntersect1(impl_->scene, &context, &query);
    if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    RayHit hit;
    hit.distance = query.ray.tfar;
    hit.triangle = query.hit.primID;
    hit.barycentric = {query.hit.u, query.hit.v};
    const glm::uvec3 t = impl_->triangles[hit.triangle];
    const glm::vec3& p0 = impl_->positions[t.x];
    hit.geometric_normal = glm::normalize(
        glm::cross(impl_->positions[t.y] - p0, impl_->positions[t.z] - p0));
    return hit;
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
        t_min = hit->distance + impl_->epsilon +
                4.0f * std::numeric_limits<float>::epsilon() * hit->distance;
    }
    return layers;
}

bool RayCaster::occluded(glm::vec3 origin, glm::vec3 direction, float t_min,
                         float t_max) const {
    const std::optional<glm::vec3> dir = unit(origin, direction);
    if (!dir || !(t_max > t_min)) return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = make_ray(origin, *dir, exclusive_near(t_min), t_max).ray;
    rtcOccluded1(impl_->scene, &context, &ray);
    return ray.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace lucent
