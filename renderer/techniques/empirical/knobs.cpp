#include "renderer/techniques/empirical/knobs.h"

#include "renderer/core/common_knobs.h"
#include "renderer/core/knob_binding.h"

namespace lucent::empirical {
namespace {

void bind(Params& p, KnobBinder& b) {
    b.knob(p.albedo, albedo_knob());
    b.knob(p.ambient, ambient_knob());
    b.knob(p.specular, specular_knob());
    b.knob(p.shininess, shininess_knob());
    b.knob(p.diffuse_contribution,
           {"diffuse_contribution", "wd: weight of the diffuse term (scalar)",
            KnobKind::scalar, 0.0, 10.0});
    b.knob(p.specular_contribution,
           {"specular_contribution", "ws: weight of the specular term (scalar)",
            KnobKind::scalar, 0.0, 10.0});
    b.knob(p.backlight,
           {"backlight",
            "wb: weight of the artificial backlight through thin parts (scalar)",
            KnobKind::scalar, 0.0, 10.0});
    b.knob(p.thickness_exponent,
           {"thickness_exponent",
            "r: exponent of (1 - thickness); larger = only the thinnest parts glow",
            KnobKind::scalar, 0.0, 10000.0});
    b.knob(p.diffuse_weight,
           {"diffuse_weight", "Kb: grey added to Kd in the backlight term (scalar)",
            KnobKind::scalar, 0.0, 10.0});
    b.knob(p.ao_rays, ao_rays_knob());
    b.knob(p.blur_kernel,
           {"blur_kernel",
            "back-layer smoothing kernel width in pixels: 1 = none, 3, 5 (thesis)",
            KnobKind::choice,
            1.0,
            5.0,
            {},
            {"1", "3", "5"}});
    b.choice(p.depth_precision, "depth_precision",
             "bits of the front/second depth-layer textures: 16, 24 or 32f (float)",
             {"16", "24", "32f"});
    b.choice(p.layer_method, "layer_method",
             "how the two depth layers are found: auto (a closed mesh: nearest front "
             "and back faces by culling; otherwise peeling) or peel (always depth "
             "peeling)",
             {"auto", "peel"});
}

}  // namespace

const std::vector<Knob>& knobs() {
    static const std::vector<Knob> list = list_knobs<Params>(bind);
    return list;
}

Params params(const Scene& scene) { return read_knobs<Params>(scene.values, bind); }

}  // namespace lucent::empirical
