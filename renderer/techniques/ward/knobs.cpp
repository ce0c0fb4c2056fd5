#include "renderer/core/common_knobs.h"
#include "renderer/techniques/ward/ward.h"

namespace lucent::ward {

const char* diffuse_knob_name(Variant variant) {
    return variant == Variant::ward ? "diffuse_reflectance" : "reversed_diffuse";
}

namespace {

std::vector<Knob> make_knobs(Variant variant) {
    const Params d{};
    Knob albedo = albedo_knob(), ambient = ambient_knob(), rays = ao_rays_knob();
    albedo.default_value = d.albedo;
    ambient.default_value = d.ambient;
    rays.default_value = d.ao_rays;
    Knob diffuse = variant == Variant::ward
                       ? Knob{"diffuse_reflectance",
                              "rho_d: Ward's diffuse reflectance (scalar)",
                              KnobKind::scalar,
                              0.0,
                              10.0,
                              d.diffuse}
                       : Knob{"reversed_diffuse",
                              "w: weight of the reversed diffuse term Id*chroma(Kd)*(1 - "
                              "Y(Kd)*max(N.L,0)) (scalar)",
                              KnobKind::scalar,
                              0.0,
                              10.0,
                              d.diffuse};
    return {albedo,
            ambient,
            diffuse,
            {"specular_reflectance", "rho_s: Ward's specular reflectance (scalar)",
             KnobKind::scalar, 0.0, 1.0, d.specular_reflectance},
            {"roughness", "alpha: rms surface slope of Ward's lobe; 0 acts as 0.001",
             KnobKind::scalar, 0.0, 1.0, d.roughness},
            rays};
}

}  // namespace

const std::vector<Knob>& knobs(Variant variant) {
    static const std::vector<Knob> ward = make_knobs(Variant::ward);
    static const std::vector<Knob> reversed = make_knobs(Variant::contrast_reversed);
    return variant == Variant::ward ? ward : reversed;
}

Params params(const Scene& scene, Variant variant) {
    const KnobValues& v = scene.values;
    Params p;
    p.albedo = v.vec3("albedo");
    p.ambient = v.scalar("ambient");
    p.diffuse = v.scalar(diffuse_knob_name(variant));
    p.specular_reflectance = v.scalar("specular_reflectance");
    p.roughness = v.scalar("roughness");
    p.ao_rays = v.integer("ao_rays");
    return p;
}

double albedo_luminance(glm::dvec3 albedo) {
    return 0.2126 * albedo.r + 0.7152 * albedo.g + 0.0722 * albedo.b;
}

glm::dvec3 albedo_chroma(glm::dvec3 albedo) {
    const double y = albedo_luminance(albedo);
    return y > 1e-6 ? albedo / y : glm::dvec3(1.0);
}

bool has_ambient_term(const Params& p, const Light& light) {
    return p.ambient != 0.0 && light.ambient != glm::vec3(0.0f);
}

bool has_specular_term(const Params& p, const Light& light) {
    return p.specular_reflectance != 0.0 && light.specular != glm::vec3(0.0f);
}

}  // namespace lucent::ward
