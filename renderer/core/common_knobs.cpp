#include "renderer/core/common_knobs.h"

#include <cstdio>

#include "renderer/core/density_volume.h"

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

namespace lucent {

std::vector<Knob> density_volume_knobs(const std::string& default_spec,
                                       int default_resolution) {
    Knob density{"density",
                 "the density volume over the mesh's bounding box: a generator "
                 "(constant, cube, spheres, marble, layers; e.g. marble:frequency=3) "
                 "or an .nrrd file",
                 KnobKind::text,
                 0.0,
                 0.0,
                 default_spec};
    density.check = [](std::string_view text) -> std::string {
        try {
            // A file is read here too, so a bad one is refused where it is named
            // (command line, config, explorer field), not later while rendering.
            if (!parse_density_spec(text).file.empty()) make_density_volume(text, 1, 1.0);
            return "";
        } catch (const DensityError& e) {
            std::string why = e.what();
            return why.rfind("density: ", 0) == 0 ? why.substr(9) : why;
        }
    };
    density.accepted =
        "constant|cube|spheres|marble|layers[:name=value,...] or FILE.nrrd";
    // The volume is an input beyond the spec's text (a file can change under the same
    // name): its content hash is recorded beside the spec, like mesh_hash.
    density.input_hash = [](const KnobValues& values) {
        return density_from_knobs(values)->content_hash;
    };
    density.describe_input = [](const KnobValues& values) {
        const auto volume = density_from_knobs(values);
        char line[256];
        std::snprintf(
            line, sizeof line, "%dx%dx%d voxels, mean %.3f, range [%.3f, %.3f], hash %s",
            volume->size.x, volume->size.y, volume->size.z, double(volume->mean),
            double(volume->min), double(volume->max), volume->content_hash.c_str());
        return std::string(line);
    };
    density.panel = "Density";
    density.suggestions = density_generator_names();
    Knob resolution = choice_knob(
        "density_resolution", "R: voxels per axis of a generated density volume",
        std::to_string(default_resolution), {"16", "32", "64", "128"});
    resolution.panel = "Density";
    Knob contrast{
        "density_contrast",
        "c: rho = clamp(mean + c (rho - mean), 0, 1); 0 = homogeneous at the mean",
        KnobKind::scalar,
        0.0,
        4.0,
        1.0};
    contrast.panel = "Density";
    return {density, resolution, contrast};
}

}  // namespace lucent
