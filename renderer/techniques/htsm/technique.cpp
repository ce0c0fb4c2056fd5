// Registers the htsm technique: Shopf's heterogeneous translucent shadow maps.
#include "core/technique.h"

#include "techniques/htsm/htsm.h"

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
        // n changes the kernel (a model parameter), so it is not swept against one
        // reference; the reference uses exact footprints and S_ref steps whatever these say.
        return {
            {"steps", {1, 2, 3, 5, 10, 20, 40}, 64},
            {"light_map_size",
             {std::string("64"), std::string("128"), std::string("256"), std::string("512")},
             std::string("512")},
            {"density_resolution",
             {std::string("16"), std::string("32"), std::string("64"), std::string("128")},
             std::string("128")},
            {"light_mips", {std::string("off"), std::string("on")}, std::string("on")},
            {"phase_table_size",
             {std::string("16"), std::string("64"), std::string("256"), std::string("1024")},
             std::string("1024")},
        };
    }
};

}  // namespace

const Technique& htsm_technique() {
    static const HtsmTechnique technique;
    return technique;
}

}  // namespace lucent
