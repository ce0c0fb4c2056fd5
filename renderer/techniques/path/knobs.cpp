// The path technique's knobs and the scene's medium in the tracer's units.
#include <algorithm>
#include <cmath>

#include "common/number_text.h"
#include "renderer/core/common_knobs.h"
#include "renderer/core/knob_binding.h"
#include "renderer/techniques/dipole/dipole.h"
#include "renderer/techniques/dipole/scattering.h"
#include "renderer/techniques/path/path.h"

namespace lucent::path {
namespace {

void bind(Params& p, KnobBinder& b) {
    // The dipole's table of measured materials (Jensen et al. 2001), so that both
    // techniques read the same numbers for a name.
    b.choice(p.material, "material",
             "Jensen et al. 2001 material (sigma_a, sigma_s' in mm^-1, eta "
             "1.3), or custom: sigma_a, sigma_s_prime and eta",
             dipole::material_choices());
    b.knob(p.sigma_a, {"sigma_a", "custom material: absorption coefficient, mm^-1 (rgb)",
                       KnobKind::rgb, 0.0, 100.0});
    b.knob(p.sigma_s_prime, {"sigma_s_prime",
                             "custom material: reduced scattering coefficient sigma_s (1 "
                             "- g), mm^-1 (rgb)",
                             KnobKind::rgb, 0.0, 1000.0});
    b.knob(p.eta,
           {"eta", "custom material: relative index of refraction (1: index-matched)",
            KnobKind::scalar, 1.0, 2.0});
    b.knob(p.g, {"g", "Henyey-Greenstein asymmetry; sigma_s = sigma_s' / (1 - g)",
                 KnobKind::scalar, -0.95, 0.95});
    b.knob(p.model_size, {"model_size", "the mesh's bounding-box diagonal in mm",
                          KnobKind::scalar, 0.1, 1000.0});
    b.knob(p.light_radius,
           {"light_radius",
            "angular radius of the key light's disc, degrees (0: a directional light, "
            "reachable only with eta = 1)",
            KnobKind::scalar, 0.0, 45.0});
    b.knob(p.paths,
           {"paths", "paths per pixel and channel", KnobKind::integer, 1.0, 1048576.0});
    b.knob(p.time_budget,
           {"time_budget",
            "seconds after which no further sample pass starts (0: none; a budget makes "
            "the image depend on the machine)",
            KnobKind::scalar, 0.0, 86400.0});
    b.knob(p.seed, {"seed", "random seed: another seed, independent samples",
                    KnobKind::integer, 0.0, 1000000.0});
    // The medium's density: make_scene builds it (density_from_knobs), no member holds
    // it.
    std::vector<Knob> volume = density_volume_knobs("constant:value=1", 32);
    volume[0].description =
        "rho: scales the material's coefficients over the mesh's bounding box (a "
        "generator, e.g. marble:frequency=3, or an .nrrd file); constant:value=1 is "
        "the homogeneous material";
    for (Knob& knob : volume) b.scene_input(std::move(knob));
}

}  // namespace

const std::vector<Knob>& knobs() {
    static const std::vector<Knob> list = list_knobs<Params>(bind);
    return list;
}

Params params(const Scene& scene) { return read_knobs<Params>(scene.values, bind); }

namespace {

dipole::Material material_of(const Params& p) {
    if (const dipole::Material* preset = dipole::find_material_preset(p.material))
        return *preset;
    return {p.sigma_a, p.sigma_s_prime, p.eta};
}

}  // namespace

double medium_eta(const Params& p) { return material_of(p).eta; }

ChannelMedium channel_medium(const Scene& scene, const Params& p, int channel) {
    const dipole::Material m = material_of(p);
    const double mm_per_unit = dipole::model_scale(*scene.mesh, p.model_size);
    ChannelMedium medium;
    medium.sigma_a = m.sigma_a[channel] * mm_per_unit;
    medium.sigma_s = m.sigma_s_prime[channel] / (1.0 - p.g) * mm_per_unit;
    medium.g = p.g;
    if (scene.density) {
        medium.density.volume = scene.density.get();
        glm::dvec3 lo(1e300), hi(-1e300);
        for (const glm::vec3& x : scene.mesh->positions) {
            lo = glm::min(lo, glm::dvec3(x));
            hi = glm::max(hi, glm::dvec3(x));
        }
        // A flat mesh's box keeps a small extent, so the mapping stays finite.
        const double floor = std::max(1e-9, 1e-6 * glm::length(hi - lo));
        medium.density.box_min = lo;
        medium.density.box_extent = glm::max(hi - lo, glm::dvec3(floor));
    }
    return medium;
}

std::vector<std::string> shortcuts_taken(const Scene& scene, const Params& p) {
    std::vector<std::string> taken;
    if (medium_eta(p) == 1.0) taken.push_back("no Fresnel events (eta = 1)");
    // sigma_s = sigma_s' / (1 - g) times a positive scale: zero exactly where sigma_s' is
    // (asked from the material itself: plan() runs every frame, and channel_medium()
    // scans every vertex for the mesh's box).
    const glm::dvec3 reduced = material_of(p).sigma_s_prime;
    const bool scatters = reduced.x > 0.0 || reduced.y > 0.0 || reduced.z > 0.0;
    if (!scatters) taken.push_back("no collisions (sigma_s = 0: Beer-Lambert weights)");
    if (scene.density && scene.density->constant())
        taken.push_back("no density lookups (constant rho = " +
                        common::shortest_text(scene.density->max) + ")");
    if (scene.light.diffuse == glm::vec3(0.0f)) taken.push_back("key light off (Id = 0)");
    if (scene.light.ambient == glm::vec3(0.0f))
        taken.push_back("environment off (Ia = 0)");
    return taken;
}

}  // namespace lucent::path
