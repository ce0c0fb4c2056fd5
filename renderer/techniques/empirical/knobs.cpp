#include "renderer/techniques/empirical/knobs.h"

#include "renderer/core/common_knobs.h"

namespace lucent::empirical {

const std::vector<Knob>& knobs() {
    static const std::vector<Knob> list = [] {
        const Params d{};
        Knob albedo = albedo_knob(), ambient = ambient_knob(), specular = specular_knob(),
             shininess = shininess_knob(), rays = ao_rays_knob();
        albedo.default_value = d.albedo;
        ambient.default_value = d.ambient;
        specular.default_value = d.specular;
        shininess.default_value = d.shininess;
        rays.default_value = d.ao_rays;
        return std::vector<Knob>{
            albedo,
            ambient,
            specular,
            shininess,
            {"diffuse_contribution", "wd: weight of the diffuse term (scalar)",
             KnobKind::scalar, 0.0, 10.0, d.diffuse_contribution},
            {"specular_contribution", "ws: weight of the specular term (scalar)",
             KnobKind::scalar, 0.0, 10.0, d.specular_contribution},
            {"backlight",
             "wb: weight of the artificial backlight through thin parts (scalar)",
             KnobKind::scalar, 0.0, 10.0, d.backlight},
            {"thickness_exponent",
             "r: exponent of (1 - thickness); larger = only the thinnest parts glow",
             KnobKind::scalar, 0.0, 10000.0, d.thickness_exponent},
            {"diffuse_weight", "Kb: grey added to Kd in the backlight term (scalar)",
             KnobKind::scalar, 0.0, 10.0, d.diffuse_weight},
            rays,
            {"blur_kernel",
             "back-layer smoothing kernel width in pixels: 1 = none, 3, 5 (thesis)",
             KnobKind::choice,
             1.0,
             5.0,
             std::to_string(d.blur_kernel),
             {"1", "3", "5"}},
            choice_knob(
                "depth_precision",
                "bits of the front/second depth-layer textures: 16, 24 or 32f (float)",
                d.depth_precision, {"16", "24", "32f"}),
            choice_knob(
                "layer_method",
                "how the two depth layers are found: auto (a closed mesh: nearest front "
                "and back faces by culling; otherwise peeling) or peel (always depth "
                "peeling)",
                d.layer_method, {"auto", "peel"}),
        };
    }();
    return list;
}

Params params(const Scene& scene) {
    const KnobValues& v = scene.values;
    Params p;
    p.albedo = v.vec3("albedo");
    p.ambient = v.scalar("ambient");
    p.specular = v.scalar("specular");
    p.shininess = v.scalar("shininess");
    p.diffuse_contribution = v.scalar("diffuse_contribution");
    p.specular_contribution = v.scalar("specular_contribution");
    p.backlight = v.scalar("backlight");
    p.thickness_exponent = v.scalar("thickness_exponent");
    p.diffuse_weight = v.scalar("diffuse_weight");
    p.ao_rays = v.integer("ao_rays");
    p.blur_kernel = std::stoi(v.choice("blur_kernel"));
    p.depth_precision = v.choice("depth_precision");
    p.layer_method = v.choice("layer_method");
    return p;
}

}  // namespace lucent::empirical
