// Registers the htsm technique: Shopf's heterogeneous translucent shadow maps.
#include "renderer/core/technique.h"

#include "renderer/techniques/htsm/htsm.h"

namespace lucent {
namespace {

class HtsmTechnique final : public Technique {
public:
    std::string_view name() const override { return "htsm"; }
    std::string_view description() const override {
        return "heterogeneous translucent shadow maps (Shopf): n rays from the light "
               "view through a density volume, transport colour and distance";
    }
    const std::vector<Knob>& knobs() const override { return htsm::knobs(); }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        htsm::add_passes(scene, plan);
    }
    Image render_reference(const Scene& scene) const override {
        return htsm::render_reference(scene, htsm::ReferenceQuality{});
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        // The reference uses exact footprints and S_ref steps whatever these say. n
        // changes the kernel (a model parameter), so it is swept against the reference of
        // each n (last row).
        return {
            {"steps", {1, 2, 3, 5, 10, 20, 40}, 64},
            {"light_map_size",
             {std::string("64"), std::string("128"), std::string("256"),
              std::string("512")},
             std::string("512")},
            {"density_resolution",
             {std::string("16"), std::string("32"), std::string("64"),
              std::string("128")},
             std::string("128")},
            {"light_mips", {std::string("off"), std::string("on")}, std::string("on")},
            {"phase_table_size",
             {std::string("16"), std::string("64"), std::string("256"),
              std::string("1024")},
             std::string("1024")},
            // n: each value against the reference of the same n-ray model (exact
            // footprints, fine march), so the row shows what the GL path's prefiltered
            // inputs cost at that n and how its frame time grows.
            {"rays",
             {std::string("1"), std::string("5"), std::string("9"), std::string("13")},
             std::string("13"),
             true},
        };
    }
    // Shopf's coefficients have no physical units, so `bench fidelity` fits them to the
    // truth; the density volume is the truth's own (the same knob names).
    std::vector<FitRange> fidelity_fit() const override {
        return {{"transport_colour", 0.0, 4.0}, {"transport_distance", 0.01, 2.0},
                {"density_scale", 0.0, 20.0},   {"diffuse", 0.0, 2.0},
                {"albedo", 0.0, 1.0},           {"specular", 0.0, 2.0}};
    }
    // Shopf's Fig. 5.9: the frame at n = 13, 9 and 5 rays against n = 1 (three GPUs:
    // 8.8-11.5x for n = 13), with the texture fetches each pixel makes.
    std::optional<FrameComparison> frame_comparison() const override {
        FrameComparison comparison{
            "torus_knot",
            {"4k"},
            {{"n=13", {{"rays", "13"}}},
             {"n=9", {{"rays", "9"}}},
             {"n=5", {{"rays", "5"}}},
             {"n=1", {{"rays", "1"}}}},
            "n = rays of the hierarchical sample pattern per pixel, "
            "the other knobs at their defaults"};
        comparison.detail = [](const Scene& scene) {
            return std::to_string(htsm::fetches_per_pixel(scene)) + " fetches per pixel";
        };
        return comparison;
    }
};

}  // namespace

const Technique& htsm_technique() {
    static const HtsmTechnique technique;
    return technique;
}

}  // namespace lucent
