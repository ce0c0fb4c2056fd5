#pragma once
// What every CPU reference renderer needs to sample a scene as the GL rasteriser does:
// one ray per pixel centre through the scene's camera (image rows top first), the
// eye-space depth of a hit, vertex attributes interpolated at a hit, rows rendered in
// parallel, and the pixel loop of the references that shade the nearest surface.
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "renderer/core/camera.h"
#include "renderer/core/image.h"
#include "renderer/core/mesh.h"
#include "renderer/cpu/ray_caster.h"

namespace lucent {

class PixelRays {
public:
    PixelRays(const Camera& camera, int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }

    glm::dvec3 eye() const { return eye_; }
    const glm::dmat4& view() const { return view_; }
    // Object space -> eye space for normals (inverse transpose of the view).
    const glm::dmat3& normal_matrix() const { return normal_matrix_; }
    // Unit direction from the eye through the centre of pixel (x, row); row 0 is the top.
    glm::dvec3 direction(int x, int row) const;
    // Through the point (offset_x, offset_y) in [0, 1]^2 of that pixel, offsets from its
    // left and bottom edges (sub-pixel rays of supersampled references); (0.5, 0.5) is
    // direction(x, row).
    glm::dvec3 direction_at(int x, int row, double offset_x, double offset_y) const;
    // Eye-space depth (distance along the viewing axis) of a point `distance` along a
    // ray with unit `direction`: what the near/far planes and the depth buffer compare.
    double eye_depth(double distance, glm::dvec3 direction) const {
        return distance * glm::dot(direction, forward_);
    }
    // The first hit the depth test keeps along the pixel ray `direction`: the nearest of
    // the first `max_hits` whose eye depth lies in [camera near, camera far).
    std::optional<RayHit> front_hit(const RayCaster& caster, glm::dvec3 direction,
                                    int max_hits = 4) const;

private:
    int width_, height_;
    double near_, far_;
    glm::dvec3 eye_, forward_;
    glm::dmat4 view_, inverse_view_projection_;
    glm::dmat3 normal_matrix_;
};

// Vertex normal (object space, not normalised) and AO interpolated at a hit with the
// barycentric weights the rasteriser uses; AO is 0 when `vertex_ao` is empty.
struct SurfaceSample {
    glm::dvec3 normal{0.0};
    double ao = 0.0;
};
SurfaceSample interpolate_at(const Mesh& mesh, const RayHit& hit,
                             const std::vector<float>& vertex_ao);

// Calls `row(y)` for every y in [0, height), spread over the hardware threads.
void for_each_row_parallel(int height, const std::function<void(int)>& row);

// The reference pixel loop (ward, contrast_reversed, dipole, htsm): every pixel ray's
// front hit (PixelRays::front_hit, rows in parallel) gets the rgb `shade(direction,
// hit)` with alpha 1; a pixel without one is `background` with alpha 0, as GL's clear.
using HitShader = std::function<glm::dvec3(glm::dvec3 direction, const RayHit& hit)>;
Image shade_front_hits(const PixelRays& rays, const RayCaster& caster,
                       glm::vec3 background, const HitShader& shade);

}  // namespace lucent
