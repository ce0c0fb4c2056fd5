#include "renderer/core/common_knobs.h"
#include "renderer/core/knob_binding.h"
#include "renderer/techniques/ward/ward.h"

namespace lucent::ward {

const char* diffuse_knob_name(Variant variant) {
    return variant == Variant::ward ? "diffuse_reflectance" : "reversed_diffuse";
}

namespace {

void bind(Params& p, KnobBinder& b, Variant variant) {
    b.knob(p.albedo, albedo_knob());
    b.knob(p.ambient, ambient_knob());
    // One member, named and meant by the variant (Eq. 14 or 15).
    const char* diffuse_meaning =
        variant == Variant::ward
            ? "rho_d: Ward's diffuse reflectance (scalar)"
            : "w: weight of the reversed diffuse term Id*chroma(Kd)*(1 - "
              "Y(Kd)*max(N.L,0)) (scalar)";
    b.knob(p.diffuse,
           {diffuse_knob_name(variant), diffuse_meaning, KnobKind::scalar, 0.0, 10.0});
    b.knob(p.specular_reflectance,
           {"specular_reflectance", "rho_s: Ward's specular reflectance (scalar)",
            KnobKind::scalar, 0.0, 1.0});
    b.knob(p.roughness,
           {"roughness", "alpha: rms surface slope of Ward's lobe; 0 acts as 0.001",
            KnobKind::scalar, 0.0, 1.0});
    b.knob(p.ao_rays, ao_rays_knob());
}

// bind() for one variant, as list_knobs and read_knobs call it.
auto bind_variant(Variant variant) {
    return [variant](Params& p, KnobBinder& b) { bind(p, b, variant); };
}

}  // namespace

const std::vector<Knob>& knobs(Variant variant) {
    static const std::vector<Knob> ward = list_knobs<Params>(bind_variant(Variant::ward));
    static const std::vector<Knob> reversed =
        list_knobs<Params>(bind_variant(Variant::contrast_reversed));
    return variant == Variant::ward ? ward : reversed;
}

Params params(const Scene& scene, Variant variant) {
    return read_knobs<Params>(scene.values, bind_variant(variant));
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
