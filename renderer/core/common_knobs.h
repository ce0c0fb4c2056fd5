#pragma once
// Knobs shared by every technique: the light, camera and background of a scene
// (scene_knobs(), added by the registry to every technique), and material knobs that
// several techniques reuse under the same canonical names.
#include <string>
#include <vector>

#include "renderer/core/knobs.h"

namespace lucent {

// light_ambient, light_diffuse, light_specular, light_direction, fov_y, background.
const std::vector<Knob>& scene_knobs();

// Material knobs a technique lists in its knobs() when it uses them.
Knob albedo_knob();     // Kd
Knob ambient_knob();    // ka
Knob specular_knob();   // ks
Knob shininess_knob();  // n
Knob ao_rays_knob();    // rays per vertex of the ambient-occlusion bake

// The density volume a technique reads (density_from_knobs): `density` (a generator spec
// or an .nrrd file, its content hash recorded as an input), `density_resolution` and
// `density_contrast`, all in the explorer's Density panel.
std::vector<Knob> density_volume_knobs(const std::string& default_spec,
                                       int default_resolution);

}  // namespace lucent
