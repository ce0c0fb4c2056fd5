// RayCaster on Embree 3: one device and one static, robust triangle scene per mesh.
#include "cpu/ray_caster.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

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

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

RTCRayHit make_ray(glm::vec3 origin, glm::vec3 unit_direction, float t_min, float t_max) {
    RTCRayHit query{};
    query.ray.org_x = origin.x;
    query.ray.org_y = origin.y;
    query.ray.org_z = origin.z;
    query.ray.dir_x = unit_direction.x;
    query.ray.dir_y = unit_direction.y;
    query.ray.dir_z = unit_direction.z;
    query.ray.tnear = t_min;
    query.ray.tfar = t_max;
    query.ray.mask = ~0u;
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
    for (const glm::uvec3& t : mesh.triangles)
        if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() ||
            t.z >= mesh.positions.size())
            throw std::invalid_argument(mesh.name +
                                        ": a triangle refers to a vertex past the "
                                        "last of " +
                                        std::to_string(mesh.positions.size()));
    impl_->positions = mesh.positions;
    impl_->triangles = mesh.triangles;
    impl_->epsilon = 1e-5f * std::max(mesh.bounding_sphere().radius, 1e-6f);
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device)
        throw std::runtime_error("Embree: cannot create a device (error " +
                                 std::to_string(rtcGetDeviceError(nullptr)) + ")");
    impl_->scene = rtcNewScene(impl_->device);
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
    if (!mesh.triangles.empty()) {
        RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Embree copies into its own (padded) buffers, so the Mesh may go away.
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
            mesh.positions.size()));
        for (std::size_t i = 0; i < mesh.positions.size(); ++i)
            for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
        auto* indices = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(unsigned), mesh.triangles.size()));
        for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
            for (int k = 0; k < 3; ++k) indices[3 * i + k] = mesh.triangles[i][k];
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(impl_->scene, geometry);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(impl_->scene);
    if (const RTCError error = rtcGetDeviceError(impl_->device); error != RTC_ERROR_NONE)
        throw std::runtime_error("Embree: scene build failed (error " +
                                 std::to_string(static_cast<int>(error)) + ")");
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

std::size_t RayCaster::count_escaping(glm::vec3 origin,
                                      const std::vector<glm::vec3>& directions,
                                      float t_min, OcclusionQuery query) const {
    if (!finite(origin)) return directions.size();  // an unusable ray hits nothing
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);  // incoherent: the rays fan out over a hemisphere
    const float near = exclusive_near(t_min);
    constexpr float kFar = std::numeric_limits<float>::infinity();
    constexpr float kBlocked = -std::numeric_limits<float>::infinity();  // Embree's mark
    std::size_t escaped = 0;
    switch (query) {
        case OcclusionQuery::single:
            for (const glm::vec3& direction : directions) {
                RTCRay ray = make_ray(origin, direction, near, kFar).ray;
                rtcOccluded1(impl_->scene, &context, &ray);
                if (ray.tfar != kBlocked) ++escaped;
            }
            break;
        case OcclusionQuery::packet8:
            for (std::size_t first = 0; first < directions.size(); first += 8) {
                alignas(32) int valid[8];
                RTCRay8 packet{};
                for (std::size_t k = 0; k < 8; ++k) {
                    const bool used = first + k < directions.size();
                    valid[k] = used ? -1 : 0;
                    const glm::vec3 d = used ? directions[first + k] : glm::vec3(0, 0, 1);
                    packet.org_x[k] = origin.x;
                    packet.org_y[k] = origin.y;
                    packet.org_z[k] = origin.z;
                    packet.dir_x[k] = d.x;
                    packet.dir_y[k] = d.y;
                    packet.dir_z[k] = d.z;
                    packet.tnear[k] = near;
                    packet.tfar[k] = kFar;
                    packet.mask[k] = ~0u;
                }
                rtcOccluded8(valid, impl_->scene, &context, &packet);
                for (std::size_t k = 0; k < 8 && first + k < directions.size(); ++k)
                    if (packet.tfar[k] != kBlocked) ++escaped;
            }
            break;
        case OcclusionQuery::stream: {
            // Reused per thread: the bake calls this once per vertex.
            thread_local std::vector<RTCRay> rays;
            rays.resize(directions.size());
            for (std::size_t i = 0; i < directions.size(); ++i)
                rays[i] = make_ray(origin, directions[i], near, kFar).ray;
            rtcOccluded1M(impl_->scene, &context, rays.data(),
                          static_cast<unsigned>(rays.size()), sizeof(RTCRay));
            for (const RTCRay& ray : rays)
                if (ray.tfar != kBlocked) ++escaped;
            break;
        }
    }
    return escaped;
}

}  // namespace lucent
