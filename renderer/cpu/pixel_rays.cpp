#include "renderer/cpu/pixel_rays.h"

#include <algorithm>
#include <glm/gtc/matrix_inverse.hpp>
#include <thread>

namespace lucent {

PixelRays::PixelRays(const Camera& camera, int width, int height)
    : width_(width),
      height_(height),
      near_(camera.near_plane),
      far_(camera.far_plane),
      eye_(camera.eye),
      forward_(glm::normalize(glm::dvec3(camera.target) - glm::dvec3(camera.eye))),
      view_(camera.view()),
      inverse_view_projection_(glm::inverse(glm::dmat4(camera.projection()) * view_)),
      normal_matrix_(glm::inverseTranspose(glm::dmat3(view_))) {}

std::optional<RayHit> PixelRays::front_hit(const RayCaster& caster, glm::dvec3 direction,
                                           int max_hits) const {
    for (const RayHit& hit :
         caster.hits(glm::vec3(eye_), glm::vec3(direction), max_hits)) {
        const double z = eye_depth(hit.distance, direction);
        if (z >= near_ && z < far_) return hit;
    }
    return std::nullopt;
}

glm::dvec3 PixelRays::direction(int x, int row) const {
    return direction_at(x, row, 0.5, 0.5);
}

glm::dvec3 PixelRays::direction_at(int x, int row, double offset_x,
                                   double offset_y) const {
    const int gl_y = height_ - 1 - row;  // image rows are top first, GL's bottom first
    // Un-project the point's far-plane point and aim at it from the eye (GL y: offset_y
    // counts from the bottom edge of the pixel).
    const glm::dvec2 ndc((x + offset_x) / width_ * 2.0 - 1.0,
                         (gl_y + offset_y) / height_ * 2.0 - 1.0);
    const glm::dvec4 far_point = inverse_view_projection_ * glm::dvec4(ndc, 1.0, 1.0);
    return glm::normalize(glm::dvec3(far_point) / far_point.w - eye_);
}

SurfaceSample interpolate_at(const Mesh& mesh, const RayHit& hit,
                             const std::vector<float>& vertex_ao) {
    const glm::uvec3 tri = mesh.triangles[hit.triangle];
    const double u = hit.barycentric.x, v = hit.barycentric.y, t = 1.0 - u - v;
    SurfaceSample sample;
    sample.normal = t * glm::dvec3(mesh.normals[tri.x]) +
                    u * glm::dvec3(mesh.normals[tri.y]) +
                    v * glm::dvec3(mesh.normals[tri.z]);
    if (!vertex_ao.empty())
        sample.ao = t * vertex_ao[tri.x] + u * vertex_ao[tri.y] + v * vertex_ao[tri.z];
    return sample;
}

void for_each_row_parallel(int height, const std::function<void(int)>& row) {
    const int threads =
        static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (int y = t; y < height; y += threads) row(y);
        });
    for (auto& thread : pool) thread.join();
}

Image shade_front_hits(const PixelRays& rays, const RayCaster& caster,
                       glm::vec3 background, const HitShader& shade) {
    Image image(rays.width(), rays.height());
    for_each_row_parallel(rays.height(), [&](int row) {
        for (int x = 0; x < rays.width(); ++x) {
            const glm::dvec3 direction = rays.direction(x, row);
            const std::optional<RayHit> front = rays.front_hit(caster, direction);
            if (!front) {
                image.set(x, row, glm::vec4(background, 0.0f));
                continue;
            }
            image.set(x, row, glm::vec4(glm::vec3(shade(direction, *front)), 1.0f));
        }
    });
    return image;
}

}  // namespace lucent
