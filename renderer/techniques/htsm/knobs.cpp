// The htsm knobs and the model functions the GL passes and the CPU reference share:
// geometry (box, Phi, light view), the hierarchical pattern, Fresnel, phase, weight.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "renderer/core/common_knobs.h"
#include "renderer/core/density_volume.h"
#include "renderer/core/knob_binding.h"
#include "renderer/techniques/htsm/htsm.h"

namespace lucent::htsm {
namespace {

Knob in_density_panel(Knob knob) {
    knob.panel = "Density";
    return knob;
}

void bind(Params& p, KnobBinder& b) {
    b.choice(p.samples, "rays",
             "n: rays per pixel in the hierarchical pattern (1 + 4 rings)",
             {"1", "5", "9", "13"});
    b.knob(p.steps, {"steps", "S: midpoint steps through the density per ray",
                     KnobKind::integer, 1.0, 64.0});
    b.choice(p.light_map_size, "light_map_size",
             "W_L: side of the light-view images (texels)",
             {"64", "128", "256", "512", "1024"});
    b.choice(p.light_mips, "light_mips",
             "on: each ring reads the mip level of its footprint (Sec. 4.3.1); "
             "off: every ray reads level 0 (point samples, no prefiltering)",
             {"off", "on"});
    // make_scene builds the volume from these three (density_from_knobs); Params holds
    // the resolution only as the place of htsm's default.
    const std::vector<Knob> volume = density_volume_knobs("marble", p.density_resolution);
    b.scene_input(volume[0]);
    b.knob(p.density_resolution, volume[1]);
    b.scene_input(volume[2]);
    b.knob(p.density_scale,
           in_density_panel(
               {"density_scale",
                "kappa: optical depth per Phi (bounding-sphere diameter) at rho = 1",
                KnobKind::scalar, 0.0, 1000.0}));
    b.choice(p.phase_table_size, "phase_table_size",
             "N_f: entries of the phase-function table", {"16", "64", "256", "1024"});
    b.knob(p.pattern_radius,
           {"pattern_radius",
            "r1: radius of the first ring, fraction of Phi (ring k: r1 2^(k-1))",
            KnobKind::scalar, 0.0, 0.5});
    b.knob(p.transport_colour, {"transport_colour", "Tc: transport colour (linear rgb)",
                                KnobKind::rgb, 0.0, 4.0});
    b.knob(p.transport_distance,
           {"transport_distance", "Td: transport distance, fraction of Phi",
            KnobKind::scalar, 1e-3, 10.0});
    b.knob(p.phase_g,
           {"phase_g", "g: Henyey-Greenstein asymmetry, normalised to f(1) = 1",
            KnobKind::scalar, 0.0, 0.8});
    b.knob(p.ior,
           {"ior", "eta: index of refraction for Schlick's Fresnel on the lit side",
            KnobKind::scalar, 1.0, 2.0});
    b.knob(p.diffuse, {"diffuse", "wd: weight of the shadowed Lambert term Kd Id N.L",
                       KnobKind::scalar, 0.0, 10.0});
    b.knob(p.albedo, albedo_knob());
    b.knob(p.specular, specular_knob());
    b.knob(p.shininess, shininess_knob());
}

}  // namespace

const std::vector<Knob>& knobs() {
    static const std::vector<Knob> list = list_knobs<Params>(bind);
    return list;
}

Params params(const Scene& scene) { return read_knobs<Params>(scene.values, bind); }

Geometry geometry(const Scene& scene, const Params& p) {
    Geometry g;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::vec3& x : scene.mesh->positions) {
        lo = glm::min(lo, glm::dvec3(x));
        hi = glm::max(hi, glm::dvec3(x));
    }
    if (scene.mesh->positions.empty()) lo = hi = glm::dvec3(0.0);
    g.phi = std::max(double(scene.bounds.diameter()), 1e-6);
    // A flat mesh would make the box extent 0 (t = (p - min) / e divides by it): pad
    // every extent to 1e-3 Phi around the centre.
    const glm::dvec3 centre = 0.5 * (lo + hi);
    g.box_extent = glm::max(hi - lo, glm::dvec3(1e-3 * g.phi));
    g.box_min = centre - 0.5 * g.box_extent;
    g.light = scene_light_view(scene);
    g.to_light = glm::dvec3(g.light.direction);
    g.texel = 2.0 * double(g.light.radius) / double(p.light_map_size);
    return g;
}

std::vector<PatternSample> pattern(const Params& p, const Geometry& g) {
    std::vector<PatternSample> out = {{{0.0, 0.0}, 0.0}};
    const double top = std::log2(double(p.light_map_size));
    const double r1 = p.pattern_radius * g.phi;
    const int rings = (p.samples - 1) / 4;
    for (int k = 1; k <= rings; ++k) {
        const double radius = r1 * std::ldexp(1.0, k - 1);
        const double lod = radius > 0.0 && p.light_mips
                               ? std::clamp(std::log2(radius / g.texel), 0.0, top)
                               : 0.0;
        for (int j = 0; j < 4; ++j) {
            const double angle = j * 0.5 * M_PI + (k - 1) * 0.25 * M_PI;
            out.push_back({radius * glm::dvec2(std::cos(angle), std::sin(angle)), lod});
        }
    }
    return out;
}

double schlick(double eta, double c) {
    if (eta == 1.0) return 0.0;
    const double f0 = ((eta - 1.0) / (eta + 1.0)) * ((eta - 1.0) / (eta + 1.0));
    const double m = 1.0 - std::clamp(c, 0.0, 1.0);
    return f0 + (1.0 - f0) * m * m * m * m * m;
}

double phase(double g, double mu) {
    if (g == 0.0) return 1.0;
    const double denominator =
        std::max(1.0 + g * g - 2.0 * g * std::clamp(mu, -1.0, 1.0), 1e-12);
    return std::pow((1.0 - g) * (1.0 - g) / denominator, 1.5);
}

double transport_weight(double tau, double td) { return std::max(0.0, 2.0 - tau / td); }

bool has_transport(const Params& p, const Scene& scene) {
    return p.transport_colour != glm::dvec3(0.0) &&
           scene.light.diffuse != glm::vec3(0.0f);
}

bool has_surface(const Params& p, const Scene& scene) {
    const bool diffuse = p.diffuse != 0.0 && p.albedo != glm::dvec3(0.0) &&
                         scene.light.diffuse != glm::vec3(0.0f);
    const bool specular = p.specular != 0.0 && scene.light.specular != glm::vec3(0.0f);
    return diffuse || specular;
}

bool density_is_constant(const Params& p, const Scene& scene) {
    return !scene.density || scene.density->constant() || p.density_scale == 0.0;
}

double constant_density(const Scene& scene) {
    return scene.density ? double(scene.density->mean) : 0.0;
}

int fetches_per_pixel(const Scene& scene) {
    const Params p = params(scene);
    int fetches = has_surface(p, scene) ? 1 : 0;
    if (has_transport(p, scene)) {
        const int per_ray = 2 + (density_is_constant(p, scene) ? 0 : p.steps) +
                            (p.phase_g != 0.0 ? 1 : 0);
        fetches += p.samples * per_ray;
    }
    return fetches;
}

}  // namespace lucent::htsm
