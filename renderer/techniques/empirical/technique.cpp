// Registers the empirical technique: its knobs, passes and CPU reference.
#include "renderer/core/technique.h"

#include "renderer/techniques/empirical/empirical.h"

namespace lucent {
namespace {

class EmpiricalTechnique final : public Technique {
public:
    std::string_view name() const override { return "empirical"; }
    std::string_view description() const override {
        return "screen-space thickness from two depth layers, backlight through thin "
               "parts, "
               "AO and Blinn-Phong (Eq. 3.6)";
    }
    const std::vector<Knob>& knobs() const override { return empirical::knobs(); }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        empirical::add_passes(scene, plan);
    }
    Image render_reference(const Scene& scene) const override {
        return empirical::render_reference(scene);
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        // Reference values: the thesis's 5x5 smoothing, exact layers (the CPU has no
        // depth buffer) and an AO bake converged well beyond the thesis's 320 rays.
        return {
            {"blur_kernel",
             {std::string("1"), std::string("3"), std::string("5")},
             std::string("5")},
            {"depth_precision",
             {std::string("16"), std::string("24"), std::string("32f")},
             std::string("32f")},
            {"ao_rays", {16, 40, 80, 160, 320}, 1024},
            // The reference's layers are exact ray hits, peeled (next hit beyond the
            // first); auto takes a closed mesh's by facing instead.
            {"layer_method",
             {std::string("peel"), std::string("auto")},
             std::string("peel")},
        };
    }
    // Eq. 3.6's appearance knobs, fitted to the path-traced truth by `bench fidelity`
    // (the exponent up to 50: Table 4.3 uses 5-25).
    std::vector<FitRange> fidelity_fit() const override {
        return {{"albedo", 0.0, 1.0},
                {"ambient", 0.0, 2.0},
                {"diffuse_contribution", 0.0, 2.0},
                {"specular", 0.0, 2.0},
                {"backlight", 0.0, 5.0},
                {"thickness_exponent", 0.5, 50.0},
                {"diffuse_weight", 0.0, 1.0}};
    }
    // The thesis's Table 4.2: the full shader against direct light only (no peeling or
    // smoothing), per mesh size.
    std::optional<FrameComparison> frame_comparison() const override {
        return FrameComparison{
            "torus_knot",
            {"4k", "30k", "60k", "120k", "240k"},
            {{"full", {}},
             {"peeled", {{"layer_method", "peel"}}},
             {"direct", {{"backlight", "0"}}}},
            "full = empirical shader (AO, two layers, 5x5 smoothing, Eq. 3.6) with the "
            "layers of the closed knot by facing; peeled = the thesis's depth peeling "
            "(layer_method peel; a few silhouette pixels differ); direct = ambient + "
            "diffuse + specular (backlight 0)"};
    }
};

}  // namespace

const Technique& empirical_technique() {
    static const EmpiricalTechnique technique;
    return technique;
}

}  // namespace lucent
