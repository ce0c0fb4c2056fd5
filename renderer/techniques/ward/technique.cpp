// Registers the ward technique: Ward's isotropic BRDF under the key light plus ambient.
#include "renderer/core/technique.h"

#include "renderer/techniques/ward/ward.h"

namespace lucent {
namespace {

class WardTechnique final : public Technique {
public:
    std::string_view name() const override { return "ward"; }
    std::string_view description() const override {
        return "opaque reference of Domon et al.: ambient*AO + Ward's isotropic BRDF "
               "(Eq. 14)";
    }
    const std::vector<Knob>& knobs() const override {
        return ward::knobs(ward::Variant::ward);
    }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        ward::add_passes(scene, plan, ward::Variant::ward);
    }
    Image render_reference(const Scene& scene) const override {
        return ward::render_reference(scene, ward::Variant::ward);
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        // The only approximation the GL path adds: the AO bake's ray count.
        return {{"ao_rays", {16, 40, 80, 160, 320}, 1024}};
    }
};

}  // namespace

const Technique& ward_technique() {
    static const WardTechnique technique;
    return technique;
}

}  // namespace lucent
