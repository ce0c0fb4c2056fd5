#pragma once
// Ward's isotropic BRDF under the key light plus an ambient term (Domon et al. Eq. 14),
// and its contrast-reversed variant (Eq. 15): what the `ward` and `contrast_reversed`
// techniques share (one shader with a variant define, one CPU reference). See README.md.
#include <glm/glm.hpp>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"

namespace lucent::ward {

enum class Variant {
    ward,               // ambient + diffuse + specular                 (Eq. 14)
    contrast_reversed,  // ambient + reversed diffuse + specular         (Eq. 15)
};

struct Params {
    glm::dvec3 albedo{0.8, 0.55, 0.35};  // Kd, linear rgb in [0, 1] (shared default)
    double ambient = 0.3;                // ka, [0, 10] (shared default)
    // ward: rho_d, the diffuse reflectance; contrast_reversed: the reversed-diffuse
    // weight. [0, 10] (Ward's energy bound is rho_d + rho_s <= 1).
    double diffuse = 0.5;
    double specular_reflectance = 0.08;  // rho_s, [0, 1]
    double roughness = 0.1;              // alpha (rms slope), [0, 1]; 0 acts as 1e-3
    int ao_rays = 320;                   // AO bake rays per vertex, [1, 4096]
    bool operator==(const Params&) const = default;
};

// The name of Params::diffuse's knob: "diffuse_reflectance" or "reversed_diffuse".
const char* diffuse_knob_name(Variant variant);
// The technique's knobs (material + technique), defaults taken from Params{}.
const std::vector<Knob>& knobs(Variant variant);
Params params(const Scene& scene, Variant variant);

// Radiance of one surface point (linear rgb). n, v: unit vectors in eye space (v towards
// the eye; the light direction comes from `light`); ao in [0, 1].
//   ambient  = ka * Ia * Kd * ao
//   diffuse  = rho_d * Kd * Id * max(N.L, 0)                     (ward)
//   reversed = w * Id * chroma * (1 - Y * max(N.L, 0))            (contrast_reversed)
//              with Y = Rec. 709 luminance of Kd and chroma = Kd / Y (albedo_chroma())
//   specular = pi * f_s(l, v) * Is * max(N.L, 0)                 (Ward's lobe,
//   ward_brdf.h)
glm::dvec3 shade(const Params& p, const Light& light, Variant variant, glm::dvec3 n,
                 glm::dvec3 v, double ao);

// Contrast reversal acts on luminance and keeps the albedo's hue: Y(Kd) (Rec. 709) and
// Kd / Y(Kd), which is white for an albedo darker than 1e-6 (no hue to keep).
double albedo_luminance(glm::dvec3 albedo);
glm::dvec3 albedo_chroma(glm::dvec3 albedo);

// Which terms can change the image (the planner and the reference agree on these).
bool has_ambient_term(const Params& p, const Light& light);
bool has_specular_term(const Params& p, const Light& light);

void add_passes(const Scene& scene, PlanBuilder& plan, Variant variant);
Image render_reference(const Scene& scene, Variant variant);

}  // namespace lucent::ward
