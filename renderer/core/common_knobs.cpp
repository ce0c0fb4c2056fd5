#include "renderer/core/common_knobs.h"

namespace lucent {

const std::vector<Knob>& scene_knobs() {
    static const std::vector<Knob> knobs = {
        {"light_ambient", "Ia: ambient intensity of the light (linear rgb)",
         KnobKind::rgb, 0.0, 100.0, glm::dvec3(0.6)},
        {"light_diffuse", "Id: diffuse intensity of the key light (linear rgb)",
         KnobKind::rgb, 0.0, 100.0, glm::dvec3(1.0)},
        {"light_specular", "Is: specular intensity of the key light (linear rgb)",
         KnobKind::rgb, 0.0, 100.0, glm::dvec3(1.0)},
        {"light_direction",
         "direction towards the key light in eye space (x right, y up, z towards the "
         "viewer); normalised on use",
         KnobKind::vec3, -1000.0, 1000.0, glm::dvec3(0.4, 0.6, 1.0)},
        {"fov_y",
         "field of view across the image's shorter side (degrees; vertical unless the "
         "image is portrait); 60 fits the bounding sphere exactly",
         KnobKind::scalar, 1.0, 170.0, 60.0},
        {"background", "colour of pixels the object does not cover (linear rgb)",
         KnobKind::rgb, 0.0, 100.0, glm::dvec3(0.0)},
    };
    return knobs;
}

Knob albedo_knob() {
    return {"albedo",      "Kd: diffuse colour of the material (linear rgb)",
            KnobKind::rgb, 0.0,
            1.0,           glm::dvec3(0.8, 0.55, 0.35)};
}
Knob ambient_knob() {
    return {"ambient",
            "ka: ambient reflectance of the material (scalar)",
            KnobKind::scalar,
            0.0,
            10.0,
            0.3};
}
Knob specular_knob() {
    return {"specular",
            "ks: specular reflectance of the material (scalar)",
            KnobKind::scalar,
            0.0,
            10.0,
            0.5};
}
Knob shininess_knob() {
    return {"shininess",
            "n: Blinn-Phong exponent (dimensionless); 0 gives a constant lobe",
            KnobKind::scalar,
            0.0,
            10000.0,
            64.0};
}
Knob ao_rays_knob() {
    return {"ao_rays",
            "rays per vertex of the ambient-occlusion bake (thesis: 320)",
            KnobKind::integer,
            1.0,
            4096.0,
            320};
}

}  // namespace lucent
