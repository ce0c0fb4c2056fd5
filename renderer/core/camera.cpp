// The thesis's camera (Eq. 3.4): distance to the bounding-sphere centre = its diameter.
#include "renderer/core/camera.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace lucent {

glm::mat4 Camera::view() const {
    const glm::vec3 forward = glm::normalize(target - eye);
    // An up vector parallel to the view direction has no defined roll: pick another axis.
    glm::vec3 safe_up = up;
    if (glm::length(glm::cross(forward, glm::normalize(up))) < 1e-4f)
        safe_up = std::abs(forward.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, -1);
    return glm::lookAt(eye, target, safe_up);
}

glm::mat4 Camera::projection() const {
    return glm::perspective(glm::radians(fov_y_degrees), aspect, near_plane, far_plane);
}

float vertical_fov_degrees(float shorter_side_fov_degrees, float aspect) {
    if (!(aspect < 1.0f) || !(aspect > 0.0f)) return shorter_side_fov_degrees;
    const double half = glm::radians(double(shorter_side_fov_degrees)) / 2.0;
    return static_cast<float>(glm::degrees(2.0 * std::atan(std::tan(half) / aspect)));
}

Camera fit_camera(const BoundingSphere& sphere, float fov_degrees, float aspect,
                  glm::vec3 view_direction) {
    // A point-like mesh (radius 0) still gets a valid frustum.
    const float radius = std::max(sphere.radius, 1e-6f);
    const float distance = 2.0f * radius;
    const float length = glm::length(view_direction);
    const glm::vec3 direction = length > 0.0f && std::isfinite(length)
                                    ? view_direction / length
                                    : glm::vec3(0, 0, 1);
    Camera camera;
    camera.target = sphere.centre;
    camera.eye = sphere.centre + direction * distance;
    camera.fov_y_degrees = vertical_fov_degrees(fov_degrees, aspect);
    camera.aspect = aspect;
    camera.near_plane = std::max(distance - radius, 1e-4f * radius);
    camera.far_plane = distance + radius;
    return camera;
}

}  // namespace lucent
