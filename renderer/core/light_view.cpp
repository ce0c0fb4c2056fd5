#include "renderer/core/light_view.h"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <stdexcept>

#include "renderer/core/scene.h"

namespace lucent {

LightView fit_light_view(const BoundingSphere& sphere, glm::vec3 to_light) {
    const float length = glm::length(to_light);
    if (!(length > 0.0f) || !std::isfinite(length))
        throw std::invalid_argument("light view: the light direction has no length");
    LightView view;
    view.direction = to_light / length;
    view.centre = sphere.centre;
    view.radius =
        std::isfinite(sphere.radius) && sphere.radius > 0.0f ? sphere.radius : 1e-6f;
    // Build the image axes: up is the hint minus its component along the light.
    const glm::vec3 hint =
        std::abs(view.direction.y) < 0.999f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1);
    view.right = glm::normalize(glm::cross(hint, view.direction));
    view.up = glm::cross(view.direction, view.right);
    const float r = view.radius;
    const glm::vec3 eye = view.centre + 2.0f * r * view.direction;
    view.view = glm::lookAt(eye, view.centre, view.up);
    view.projection = glm::ortho(-r, r, -r, r, r, 3.0f * r);
    view.view_projection = view.projection * view.view;
    return view;
}

glm::vec3 light_direction_object(const Scene& scene) {
    return glm::inverse(glm::mat3(scene.camera.view())) * scene.light.direction;
}

LightView scene_light_view(const Scene& scene) {
    return fit_light_view(scene.bounds, light_direction_object(scene));
}

}  // namespace lucent
