#pragma once
// The key light's view of the object: an orthographic camera looking along the light,
// fitted to the bounding sphere. One GL-free function so the GL passes (shadow and
// light-space maps: dipole visibility, HTSM light view) and the CPU references project
// identically.
#include <glm/glm.hpp>

#include "renderer/core/mesh.h"

namespace lucent {

struct Scene;

struct LightView {
    glm::vec3 direction{0.0f, 0.0f, 1.0f};  // unit, object space, towards the light
    glm::vec3 centre{0.0f};                 // of the bounding sphere
    float radius = 1.0f;                    // R_L, of the bounding sphere (> 0)
    // Object-space unit axes of the light image: u to the right, v up; (right, up,
    // direction) is a right-handed orthonormal frame.
    glm::vec3 right{1.0f, 0.0f, 0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    // Object -> light eye (looking down -z, eye at centre + 2R direction) and light eye
    // -> clip: x, y in [-R, R] map to [-1, 1], the sphere's depth span [R, 3R] to z_ndc
    // [-1, 1], so window depth = (distance from the eye - R) / 2R.
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    glm::mat4 view_projection{1.0f};

    // World size of one texel of a `resolution`^2 light image.
    float texel_size(int resolution) const { return 2.0f * radius / float(resolution); }
};

// Fits the view to `sphere` for a light towards `to_light` (object space, any length >
// 0; std::invalid_argument for zero or non-finite). A radius <= 0 (a point-like mesh) is
// treated as 1e-6 so the matrices stay finite. The up axis is the projection of +y (of +z
// when the light is within ~2.6 degrees of the y axis).
LightView fit_light_view(const BoundingSphere& sphere, glm::vec3 to_light);

// The scene's key light in object space: its light direction is in eye space, so
// L_obj = inverse(mat3(view)) L_eye.
glm::vec3 light_direction_object(const Scene& scene);
LightView scene_light_view(const Scene& scene);

}  // namespace lucent
