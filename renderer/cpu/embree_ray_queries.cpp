// The Embree 3 implementation of the core's ray queries (core/cpu_backend.h): one device
// and one static, robust triangle scene per mesh.
#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <memory>

#include "renderer/core/cpu_backend.h"
#include "renderer/cpu/embree_backend.h"
#include "renderer/cpu/embree_support.h"
#include "renderer/cpu/ray_caster.h"

namespace lucent {
namespace {

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

class EmbreeRayQueries : public RayQueries {
public:
    explicit EmbreeRayQueries(const Mesh& mesh)
        : positions_(mesh.positions), triangles_(mesh.triangles) {
        embree::check_indices(mesh);
        device_ = embree::new_device();
        scene_ = embree::build_scene(device_, mesh);
    }
    ~EmbreeRayQueries() override {
        if (scene_) rtcReleaseScene(scene_);
        if (device_) rtcReleaseDevice(device_);
    }
    EmbreeRayQueries(const EmbreeRayQueries&) = delete;
    EmbreeRayQueries& operator=(const EmbreeRayQueries&) = delete;

    std::optional<RayHit> first_hit(glm::vec3 origin, glm::vec3 dir, float t_min,
                                    float t_max) const override {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit query = make_ray(origin, dir, exclusive_near(t_min), t_max);
        rtcIntersect1(scene_, &context, &query);
        if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
        RayHit hit;
        hit.distance = query.ray.tfar;
        hit.triangle = query.hit.primID;
        hit.barycentric = {query.hit.u, query.hit.v};
        const glm::uvec3 t = triangles_[hit.triangle];
        const glm::vec3& p0 = positions_[t.x];
        hit.geometric_normal =
            glm::normalize(glm::cross(positions_[t.y] - p0, positions_[t.z] - p0));
        return hit;
    }

    bool occluded(glm::vec3 origin, glm::vec3 dir, float t_min,
                  float t_max) const override {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray = make_ray(origin, dir, exclusive_near(t_min), t_max).ray;
        rtcOccluded1(scene_, &context, &ray);
        return ray.tfar == -std::numeric_limits<float>::infinity();
    }

private:
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    std::vector<glm::vec3> positions_;  // copies: hit normals are computed from them
    std::vector<glm::uvec3> triangles_;
};

}  // namespace

std::unique_ptr<RayQueries> make_embree_ray_queries(const Mesh& mesh) {
    return std::make_unique<EmbreeRayQueries>(mesh);
}

}  // namespace lucent
