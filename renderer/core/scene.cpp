#include "renderer/core/scene.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/technique.h"

namespace lucent {

Scene make_scene(std::shared_ptr<const Mesh> mesh, const Technique& technique,
                 KnobValues values, int width, int height, glm::vec3 view_direction) {
    Scene scene;
    scene.bounds = mesh->bounding_sphere();
    scene.mesh = std::move(mesh);
    scene.technique = std::string(technique.name());
    scene.light.ambient = glm::vec3(values.vec3("light_ambient"));
    scene.light.diffuse = glm::vec3(values.vec3("light_diffuse"));
    scene.light.specular = glm::vec3(values.vec3("light_specular"));
    // The knob rejects the zero vector, so the normalisation is safe.
    scene.light.direction = glm::vec3(glm::normalize(values.vec3("light_direction")));
    scene.background = glm::vec3(values.vec3("background"));
    scene.density = density_from_knobs(values);
    scene.values = std::move(values);
    fit_scene_camera(scene, width, height, view_direction);
    return scene;
}

void fit_scene_camera(Scene& scene, int width, int height, glm::vec3 view_direction) {
    scene.width = width;
    scene.height = height;
    scene.camera = fit_camera(
        scene.bounds, static_cast<float>(scene.values.scalar("fov_y")),
        static_cast<float>(width) / static_cast<float>(height), view_direction);
    // Widen near/far by a hair so the nearest and farthest points of the bounding sphere
    // survive clipping and the depth test against the cleared depth (1.0); thickness uses
    // eye-space distances, so this does not change it.
    const float margin = 1e-3f * scene.bounds.radius;
    scene.camera.near_plane =
        std::max(scene.camera.near_plane - margin, 0.5f * scene.camera.near_plane);
    scene.camera.far_plane += margin;
}

bool facing_separates_layers(const Scene& scene) {
    if (!scene.mesh || !scene.mesh->closed_facing_out) return false;
    const float distance = glm::distance(scene.camera.eye, scene.bounds.centre);
    // The view ray first meets the sphere at distance - radius: the near plane must lie
    // before it, or a clipped solid shows its inside (back faces) first.
    return std::isfinite(distance) && distance > scene.bounds.radius &&
           scene.camera.near_plane <= distance - scene.bounds.radius;
}

}  // namespace lucent
