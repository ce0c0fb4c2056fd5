#include "renderer/cpu/embree_support.h"

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#endif

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace lucent::embree {

RTCDevice new_device(const char* config) {
    RTCDevice device = rtcNewDevice(config);
    if (!device)
        throw std::runtime_error("Embree: cannot create a device (error " +
                                 std::to_string(rtcGetDeviceError(nullptr)) + ")");
    return device;
}

void check(RTCDevice device, const std::string& what) {
    if (const RTCError error = rtcGetDeviceError(device); error != RTC_ERROR_NONE)
        throw std::runtime_error("Embree: " + what + " failed (error " +
                                 std::to_string(static_cast<int>(error)) + ")");
}

void check_indices(const Mesh& mesh) {
    for (const glm::uvec3& t : mesh.triangles)
        if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() ||
            t.z >= mesh.positions.size())
            throw std::invalid_argument(mesh.name +
                                        ": a triangle refers to a vertex past the "
                                        "last of " +
                                        std::to_string(mesh.positions.size()));
}

RTCScene build_scene(RTCDevice device, const Mesh& mesh,
                     const std::vector<glm::uvec4>* quads) {
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    if (!mesh.triangles.empty()) {
        RTCGeometry geometry = rtcNewGeometry(
            device, quads ? RTC_GEOMETRY_TYPE_QUAD : RTC_GEOMETRY_TYPE_TRIANGLE);
        // Embree copies into its own (padded) buffers, so the Mesh may go away.
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
            mesh.positions.size()));
        for (std::size_t i = 0; i < mesh.positions.size(); ++i)
            for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
        if (quads) {
            auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
                geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                4 * sizeof(unsigned), quads->size()));
            std::memcpy(indices, quads->data(), quads->size() * sizeof(glm::uvec4));
        } else {
            auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
                geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                3 * sizeof(unsigned), mesh.triangles.size()));
            std::memcpy(indices, mesh.triangles.data(),
                        mesh.triangles.size() * sizeof(glm::uvec3));
        }
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene, geometry);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
        rtcReleaseScene(scene);
        check(device, "scene build");
    }
    return scene;
}

RTCRay make_ray(glm::vec3 origin, glm::vec3 direction, float t_near, float t_far) {
    RTCRay ray{};
    ray.org_x = origin.x;
    ray.org_y = origin.y;
    ray.org_z = origin.z;
    ray.dir_x = direction.x;
    ray.dir_y = direction.y;
    ray.dir_z = direction.z;
    ray.tnear = t_near;
    ray.tfar = t_far;
    ray.mask = ~0u;
    return ray;
}

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

#if defined(__x86_64__) || defined(__i386__)
namespace {
constexpr unsigned kFlushToZero = 0x8000;
constexpr unsigned kDenormalsAreZero = 0x0040;
}  // namespace
FlushDenormals::FlushDenormals() : saved_(_mm_getcsr()) {
    _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero);
}
FlushDenormals::~FlushDenormals() { _mm_setcsr(saved_); }
#else
FlushDenormals::FlushDenormals() = default;  // elsewhere: Embree's default
FlushDenormals::~FlushDenormals() = default;
#endif

}  // namespace lucent::embree
