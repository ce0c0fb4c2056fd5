// Registers the contrast_reversed technique (Domon et al. Eq. 15): Ward's model with the
// diffuse term reversed. It shares ward's shader (variant REVERSED_DIFFUSE), planner and
// CPU reference; only the diffuse term and its knob differ. See README.md beside this
// file.
#include "renderer/core/technique.h"

#include "renderer/techniques/ward/ward.h"

namespace lucent {
namespace {

class ContrastReversedTechnique final : public Technique {
public:
    std::string_view name() const override { return "contrast_reversed"; }
    std::string_view description() const override {
        return "translucent look by contrast reversal (Domon et al. Eq. 15): ambient*AO "
               "+ "
               "reversed diffuse + Ward specular, on black";
    }
    const std::vector<Knob>& knobs() const override {
        return ward::knobs(ward::Variant::contrast_reversed);
    }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        ward::add_passes(scene, plan, ward::Variant::contrast_reversed);
    }
    Image render_reference(const Scene& scene) const override {
        return ward::render_reference(scene, ward::Variant::contrast_reversed);
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        // The only approximation the GL path adds: the AO bake's ray count.
        return {{"ao_rays", {16, 40, 80, 160, 320}, 1024}};
    }
};

}  // namespace

const Technique& contrast_reversed_technique() {
    static const ContrastReversedTechnique technique;
    return technique;
}

}  // namespace lucent
