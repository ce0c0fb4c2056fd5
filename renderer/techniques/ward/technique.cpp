// Registers the ward and contrast_reversed techniques: one class, registered twice with
// its variant (Domon et al. Eq. 14, Ward's isotropic BRDF under the key light plus
// ambient; Eq. 15, the same model with the diffuse term reversed). They share the
// shader (variant REVERSED_DIFFUSE), planner and CPU reference; only the diffuse term
// and its knob differ. contrast_reversed/README.md describes the second.
#include "renderer/core/technique.h"

#include "renderer/techniques/ward/ward.h"

namespace lucent {
namespace {

class WardTechnique final : public Technique {
public:
    WardTechnique(ward::Variant variant, std::string_view name,
                  std::string_view description)
        : variant_(variant), name_(name), description_(description) {}
    std::string_view name() const override { return name_; }
    std::string_view description() const override { return description_; }
    const std::vector<Knob>& knobs() const override { return ward::knobs(variant_); }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        ward::add_passes(scene, plan, variant_);
    }
    Image render_reference(const Scene& scene) const override {
        return ward::render_reference(scene, variant_);
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        // The only approximation the GL path adds: the AO bake's ray count.
        return {{"ao_rays", {16, 40, 80, 160, 320}, 1024}};
    }
    // Appearance knobs, fitted to the path-traced truth by `bench fidelity`.
    std::vector<FitRange> fidelity_fit() const override {
        return {
            {"albedo", 0.0, 1.0},
            {"ambient", 0.0, 2.0},
            {variant_ == ward::Variant::ward ? "diffuse_reflectance" : "reversed_diffuse",
             0.0, 1.0},
            {"specular_reflectance", 0.0, 0.5},
            {"roughness", 0.01, 0.5}};
    }

private:
    ward::Variant variant_;
    std::string_view name_, description_;
};

}  // namespace

const Technique& ward_technique() {
    static const WardTechnique technique(
        ward::Variant::ward, "ward",
        "opaque reference of Domon et al.: ambient*AO + Ward's isotropic BRDF (Eq. 14)");
    return technique;
}

const Technique& contrast_reversed_technique() {
    static const WardTechnique technique(
        ward::Variant::contrast_reversed, "contrast_reversed",
        "translucent look by contrast reversal (Domon et al. Eq. 15): ambient*AO + "
        "reversed diffuse + Ward specular, on black");
    return technique;
}

}  // namespace lucent
