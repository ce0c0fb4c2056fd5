// Registers the thick_texture technique: David-Babin's semi-transparent textures of
// opaque and transparent texels with a thickness.
#include "renderer/core/technique.h"

#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent {
namespace {

class ThickTextureTechnique final : public Technique {
public:
    std::string_view name() const override { return "thick_texture"; }
    std::string_view description() const override {
        return "see-through sheets: binary textures whose opaque texels have a thickness "
               "(David-Babin 2022), over a backdrop; needs a mesh with UVs";
    }
    const std::vector<Knob>& knobs() const override { return thick_texture::knobs(); }
    void check_scene(const Scene& scene) const override {
        thick_texture::require_uvs(*scene.mesh);
        thick_texture::scene_texture(thick_texture::params(scene));  // parses the spec
    }
    void plan(const Scene& scene, PlanBuilder& plan) const override {
        thick_texture::add_passes(scene, plan);
    }
    Image render_reference(const Scene& scene) const override {
        return thick_texture::render_reference(scene);
    }
    std::vector<QualitySweep> quality_sweeps() const override {
        return {
            {"filter",
             {std::string("nearest"), std::string("linear"), std::string("bilinear"),
              std::string("trilinear")},
             std::string("trilinear")},
            {"fetch_path",
             {std::string("hardware"), std::string("thesis")},
             std::string("hardware")},
            {"wide_hole_bins",
             {std::string("1"), std::string("4"), std::string("8")},
             std::string("1")},
            // Scene knobs, each row against its own reference: the model's error grows
            // with h tan(theta) once holes wider than a texel lose their far walls.
            {"thickness", {0.1, 0.5, 1.0, 2.0}, 1.0, true},
            {"tilt", {0.0, 30.0, 60.0, 75.0, 85.0}, 0.0, true},
        };
    }
    // David-Babin's Table 4.1: the thick texture (fast path and the thesis's 8-texel
    // path) against the same sheet with a plain alpha texture, 100 to 12,800 triangles.
    std::optional<FrameComparison> frame_comparison() const override {
        return FrameComparison{
            "wave",
            {"100", "400", "800", "3200", "9600", "12800"},
            {{"thick", {}},
             {"thesis", {{"fetch_path", "thesis"}}},
             {"alpha", {{"thickness", "0"}}}},
            "thick = Alg. 3.1 on hardware-filtered averages; thesis = 8 texels x Alg. "
            "3.1; "
            "alpha = the same sheet with h = 0 (a plain alpha texture)"};
    }
};

}  // namespace

const Technique& thick_texture_technique() {
    static const ThickTextureTechnique technique;
    return technique;
}

}  // namespace lucent
