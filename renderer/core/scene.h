#pragma once
// A scene: what one image shows. Mesh, fitted camera, key light, background, and the
// technique with a value for each of its knobs (material and technique parameters).
// GL-free; the frame plan and the CPU references are pure functions of a Scene.
#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "renderer/core/camera.h"
#include "renderer/core/density_volume.h"
#include "renderer/core/knobs.h"
#include "renderer/core/mesh.h"

namespace lucent {

class Technique;

// One directional key light plus an ambient term (thesis Sec. 3.1.1).
struct Light {
    glm::vec3 ambient{0.6f};                // Ia, linear rgb
    glm::vec3 diffuse{1.0f};                // Id
    glm::vec3 specular{1.0f};               // Is
    glm::vec3 direction{0.0f, 0.0f, 1.0f};  // unit, towards the light, eye space
};

struct Scene {
    std::shared_ptr<const Mesh> mesh;
    // Density over the mesh's bounding box, for techniques with a "density" knob (htsm);
    // built from the knobs by make_scene, null otherwise.
    std::shared_ptr<const DensityVolume> density;
    BoundingSphere bounds;  // of `mesh`; its diameter normalises thickness (Eq. 3.4)
    Camera camera;
    Light light;
    glm::vec3 background{0.0f};  // linear rgb
    std::string technique;       // registry name
    KnobValues values;           // every knob of scene_knobs() + the technique's knobs
    int width = 512;             // image size in pixels
    int height = 512;
};

// Builds a scene whose light, background and camera (fitted as in the thesis with the
// `fov_y` knob, looking along -`view_direction`) come from `values`.
Scene make_scene(std::shared_ptr<const Mesh> mesh, const Technique& technique,
                 KnobValues values, int width, int height,
                 glm::vec3 view_direction = {0.0f, 0.0f, 1.0f});
// Sets the image size and fits the camera to it as make_scene() does (the mesh, density
// and values stay: a resolved scene drawn at another size loads nothing again).
void fit_scene_camera(Scene& scene, int width, int height,
                      glm::vec3 view_direction = {0.0f, 0.0f, 1.0f});

// True when a mesh pass may drop triangles by facing and keep the same layers: the mesh
// bounds a solid facing out (Mesh::closed_facing_out) and the camera sees all of it from
// outside (the eye outside the bounding sphere, the near plane in front of it). Then
// the nearest surface of every pixel faces the viewer and the one right behind it faces
// away (FaceCulling).
bool facing_separates_layers(const Scene& scene);

}  // namespace lucent
