#include <algorithm>
#include <cmath>

#include "renderer/core/common_knobs.h"
#include "renderer/core/knob_binding.h"
#include "renderer/cpu/blinn_phong.h"
#include "renderer/techniques/dipole/dipole.h"

namespace lucent::dipole {

std::vector<std::string> material_choices() {
    std::vector<std::string> choices;
    for (const auto& preset : material_presets()) choices.push_back(preset.name);
    choices.push_back("custom");
    return choices;
}

namespace {

void bind(Params& p, KnobBinder& b) {
    b.choice(p.material, "material",
             "Jensen et al. 2001 material (sigma_a, sigma_s' in mm^-1, eta 1.3), or "
             "custom: sigma_a, sigma_s_prime and eta",
             material_choices());
    b.knob(p.sigma_a, {"sigma_a", "custom material: absorption coefficient, mm^-1 (rgb)",
                       KnobKind::rgb, 0.0, 100.0});
    b.knob(
        p.sigma_s_prime,
        {"sigma_s_prime", "custom material: reduced scattering coefficient, mm^-1 (rgb)",
         KnobKind::rgb, 0.0, 1000.0});
    b.knob(p.eta, {"eta", "custom material: relative index of refraction",
                   KnobKind::scalar, 1.0, 2.0});
    b.knob(p.model_size,
           {"model_size", "the mesh's bounding-box diagonal in mm (the paper's '10 mm')",
            KnobKind::scalar, 0.1, 1000.0});
    b.knob(p.samples,
           {"samples", "N: texture-space importance samples shared by every pixel",
            KnobKind::integer, 1.0, 65536.0});
    b.choice(p.atlas_resolution, "atlas_resolution",
             "side of the surfel atlas of irradiance (texels)",
             {"256", "512", "1024", "2048"});
    b.choice(p.hybrid, "hybrid",
             "Sec. 4 hybrid: local part from the light view (L rings x C + 1), "
             "global part by texture-space sampling",
             {"off", "on"});
    b.knob(p.rings, {"rings", "L: rings of the local pattern (hybrid)", KnobKind::integer,
                     1.0, 32.0});
    b.knob(p.ring_samples,
           {"ring_samples", "C: samples per ring of the local pattern (hybrid)",
            KnobKind::integer, 1.0, 32.0});
    b.knob(p.importance_bound,
           {"importance_bound",
            "c: Rp is the largest r with 2 pi r Rd(r) = c, per channel (mm^-1; hybrid)",
            KnobKind::scalar, 0.001, 10.0});
    b.knob(p.hybrid_k,
           {"hybrid_k", "K: steepness of the local weight around Rp (mm^-1; hybrid)",
            KnobKind::scalar, 0.01, 100.0});
    b.choice(p.light_map_resolution, "light_map_resolution",
             "side of the light-view depth/flux maps (visibility, hybrid local part)",
             {"256", "512", "1024"});
    b.knob(p.sample_seed,
           {"sample_seed", "stratification offset xi = frac(0.5 + seed * 0.618...)",
            KnobKind::integer, 0.0, 1000000.0});
    b.choice(p.tone_map, "tone_map", "none (linear radiance) or reinhard s/(1+s)",
             {"none", "reinhard"});
    b.knob(p.tone_key, {"tone_key", "a: Reinhard key, s = a L / L_avg", KnobKind::scalar,
                        0.001, 100.0});
    b.knob(p.specular, specular_knob());
    b.knob(p.shininess, shininess_knob());
    b.knob(p.ambient, ambient_knob());
    b.knob(p.ao_rays, ao_rays_knob());
}

}  // namespace

const std::vector<Knob>& knobs() {
    static const std::vector<Knob> list = list_knobs<Params>(bind);
    return list;
}

Params params(const Scene& scene) { return read_knobs<Params>(scene.values, bind); }

Material material_of(const Params& p) {
    if (const Material* preset = find_material_preset(p.material)) return *preset;
    return {p.sigma_a, p.sigma_s_prime, p.eta};
}

double model_scale(const Mesh& mesh, double model_size_mm) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::vec3& p : mesh.positions) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    const double diagonal = mesh.positions.empty() ? 0.0 : glm::length(hi - lo);
    return diagonal > 0.0 && std::isfinite(diagonal) ? model_size_mm / diagonal : 1.0;
}

glm::dvec3 light_in_object_space(const Scene& scene) {
    // The view is a rigid motion, so its inverse rotation is the transpose.
    const glm::dmat3 rotation(glm::dmat4(scene.camera.view()));
    return glm::normalize(glm::transpose(rotation) * glm::dvec3(scene.light.direction));
}

bool has_subsurface_term(const Params& p, const Scene& scene) {
    const DipoleRgb d(material_of(p));
    const glm::dvec3 id = scene.light.diffuse;
    for (int c = 0; c < 3; ++c)
        if (id[c] != 0.0 && d[c].scatters() && d[c].albedo() > 0.0) return true;
    return false;
}

bool has_specular_term(const Params& p, const Scene& scene) {
    return p.specular != 0.0 && scene.light.specular != glm::vec3(0.0f);
}

bool has_ambient_term(const Params& p, const Scene& scene) {
    if (p.ambient == 0.0 || scene.light.ambient == glm::vec3(0.0f)) return false;
    const glm::dvec3 rd = DipoleRgb(material_of(p)).total_reflectance();
    return rd != glm::dvec3(0.0);
}

glm::dvec3 reinhard(glm::dvec3 radiance, double key, double average_luminance) {
    if (!(average_luminance > 0.0)) return glm::dvec3(0.0);
    const glm::dvec3 s = glm::max(radiance, glm::dvec3(0.0)) * (key / average_luminance);
    return s / (glm::dvec3(1.0) + s);
}

double tone_map_average(const Params& p, const Scene& scene, double flux_per_id,
                        double total_area_mm2) {
    const glm::dvec3 rd = DipoleRgb(material_of(p)).total_reflectance();
    const glm::dvec3 id = scene.light.diffuse;
    const double y = 0.2126 * rd.r * id.r + 0.7152 * rd.g * id.g + 0.0722 * rd.b * id.b;
    return total_area_mm2 > 0.0 ? y * flux_per_id / (kPi * total_area_mm2) : 0.0;
}

glm::dvec3 blinn_phong(const Params& p, const Light& light, glm::dvec3 n) {
    const glm::dvec3 l = light.direction;
    if (!(glm::dot(n, l) > 0.0)) return glm::dvec3(0.0);
    return p.specular * glm::dvec3(light.specular) * blinn_phong_lobe(n, l, p.shininess);
}

glm::dvec3 ambient_term(const Params& p, const Light& light, double n_dot_v, double ao) {
    const Material m = material_of(p);
    const glm::dvec3 kd = fresnel_transmittance(m.eta, n_dot_v) *
                          mean_fresnel_transmittance(m.eta) *
                          DipoleRgb(m).total_reflectance();
    return p.ambient * glm::dvec3(light.ambient) * kd * ao;
}

}  // namespace lucent::dipole
