#pragma once
// The camera of the thesis: it looks at the bounding-sphere centre from a distance equal
// to the bounding-sphere diameter, with near/far planes hugging the sphere.
#include <glm/glm.hpp>

#include "renderer/core/mesh.h"

namespace lucent {

struct Camera {
    glm::vec3 eye{0.0f, 0.0f, 1.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_degrees = 45.0f;  // vertical field of view of the projection
    float aspect = 1.0f;          // width / height
    float near_plane = 0.1f;      // eye-space distances, > 0
    float far_plane = 10.0f;

    glm::mat4 view() const;        // right-handed, looking down -Z in eye space
    glm::mat4 projection() const;  // OpenGL clip space (z_ndc in [-1, 1])
};

// Camera fitted to `sphere`: eye at centre + direction * diameter (direction normalised;
// default +Z), near = diameter - radius, far = diameter + radius (clamped to stay > 0).
// `fov_degrees` spans the image's shorter side, so the sphere fits both axes: it is the
// vertical field of view of a square or landscape image (aspect >= 1) and the horizontal
// one of a portrait image, whose vertical field of view then follows from the aspect
// (vertical_fov_degrees). GL and the CPU references both project through this camera.
Camera fit_camera(const BoundingSphere& sphere, float fov_degrees, float aspect,
                  glm::vec3 view_direction = {0.0f, 0.0f, 1.0f});

// The vertical field of view (degrees) of an image of `aspect` (width / height) whose
// shorter side spans `shorter_side_fov_degrees`: unchanged for aspect >= 1; for a
// portrait image tan(fov_y / 2) = tan(shorter_side_fov / 2) / aspect.
float vertical_fov_degrees(float shorter_side_fov_degrees, float aspect);

}  // namespace lucent
