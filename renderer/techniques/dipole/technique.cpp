// Registers the dipole technique: Chang et al.'s texture-space importance sampling of
// Jensen's dipole BSSRDF, in physical units.
#include "renderer/core/technique.h"

#include "renderer/techniques/dipole/dipole.h"

namespace lucent {
namespace {

class DipoleTechnique final : public Technique {
public:
    std::string_view name() const override { return "dipole"; }
    std::string_view description() const override {
        return "physically based: Jensen's dipole BSSRDF by texture-space importance "
               "sampling (Chang et al.), optional local/global hybrid, in mm";
    }
    const std::vector<Knob>& knobs() const override { return dipole::knobs(); }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        dipole::add_passes(scene, plan);
    }
    Image render_reference(const Scene& scene) const override {
        return dipole::render_reference(scene, dipole::IntegratorQuality{});
    }
    // The translucency pass costs pixels x N: an interactive frame (5 fps at 640x720 on
    // llvmpipe, measured by `lucent bench frame --technique dipole`) takes 4 samples, and
    // the view refines to the set's N while nothing changes.
    ProgressiveRefinement progressive_refinement() const override {
        return {"samples", "sample_seed", 4};
    }
    // The material is physics and comes from the truth as it is; the ambient and
    // Blinn-Phong terms are appearance, so `bench fidelity` fits them.
    std::vector<FitRange> fidelity_fit() const override {
        return {{"ambient", 0.0, 2.0}, {"specular", 0.0, 2.0}, {"shininess", 1.0, 200.0}};
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        // The CPU reference integrates Eq. 3 directly; it uses none of these.
        return {
            {"samples", {49, 100, 169, 256, 400, 900, 1600, 2500}, 2500},
            {"atlas_resolution",
             {std::string("256"), std::string("512"), std::string("1024")},
             std::string("1024")},
            {"light_map_resolution",
             {std::string("256"), std::string("512"), std::string("1024")},
             std::string("1024")},
            // Plain sampling against the hybrid (N global + L C + 1 local).
            {"hybrid", {std::string("off"), std::string("on")}, std::string("off")},
            // The local pattern's L rings x C samples, which matter only with the hybrid.
            {"rings", {2, 5, 10, 20, 32}, 20, false, {{"hybrid", std::string("on")}}},
            {"ring_samples",
             {4, 8, 12, 20, 32},
             20,
             false,
             {{"hybrid", std::string("on")}}},
        };
    }
};

}  // namespace

const Technique& dipole_technique() {
    static const DipoleTechnique technique;
    return technique;
}

}  // namespace lucent
