// The ward and contrast_reversed techniques: GL-free planning, the shading equations at
// analytic points, and GL against the CPU reference on built-in meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "renderer/core/image_compare.h"
#include "renderer/core/technique.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "renderer/techniques/ward/ward.h"
#include "renderer/techniques/ward/ward_brdf.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/scene_for_test.h"

namespace lucent {
namespace {

Scene scene_for(const std::string& technique, std::vector<KnobAssignment> settings,
                const std::string& mesh = "sphere:2k", int size = 96) {
    return test::scene_for(technique, std::move(settings), mesh, size);
}

bool has_define(const Pass& pass, const std::string& define) {
    return std::find(pass.shader.defines.begin(), pass.shader.defines.end(), define) !=
           pass.shader.defines.end();
}

using test::find_pass;

TEST(WardPlan, BothTechniquesAreRegistered) {
    EXPECT_EQ(find_technique("ward").name(), "ward");
    EXPECT_EQ(find_technique("contrast_reversed").name(), "contrast_reversed");
    EXPECT_NE(find_knob(find_technique("contrast_reversed").knobs(), "reversed_diffuse"),
              nullptr);
    EXPECT_NE(find_knob(find_technique("ward").knobs(), "diffuse_reflectance"), nullptr);
}

TEST(WardPlan, ZeroAmbientCullsTheAoBake) {
    for (const char* name : {"ward", "contrast_reversed"}) {
        const Scene on = scene_for(name, {{"ambient", "0.2"}});
        const Scene off = scene_for(name, {{"ambient", "0"}});
        const Scene no_light = scene_for(name, {{"light_ambient", "0"}});
        const auto& technique = find_technique(name);
        EXPECT_NE(find_pass(make_frame_plan(on, technique), "ambient_occlusion"), nullptr)
            << name;
        EXPECT_EQ(find_pass(make_frame_plan(off, technique), "ambient_occlusion"),
                  nullptr)
            << name;
        EXPECT_EQ(find_pass(make_frame_plan(no_light, technique), "ambient_occlusion"),
                  nullptr)
            << name;
        // Full mode keeps every pass, so pruning can be checked against it.
        EXPECT_NE(find_pass(make_frame_plan(off, technique, PlanMode::full),
                            "ambient_occlusion"),
                  nullptr);
    }
}

TEST(WardPlan, VariantDefinesFollowTheScene) {
    const auto reversed = make_frame_plan(scene_for("contrast_reversed", {}),
                                          find_technique("contrast_reversed"));
    const auto ward_plan = make_frame_plan(scene_for("ward", {}), find_technique("ward"));
    EXPECT_TRUE(has_define(*find_pass(reversed, "shade"), "REVERSED_DIFFUSE"));
    EXPECT_FALSE(has_define(*find_pass(ward_plan, "shade"), "REVERSED_DIFFUSE"));
    const auto matte = make_frame_plan(scene_for("ward", {{"specular_reflectance", "0"}}),
                                       find_technique("ward"));
    EXPECT_FALSE(has_define(*find_pass(matte, "shade"), "WITH_SPECULAR"));
    EXPECT_TRUE(has_define(*find_pass(ward_plan, "shade"), "WITH_SPECULAR"));
}

TEST(WardShading, AnalyticPoints) {
    ward::Params p;
    p.albedo = {0.2, 0.5, 0.8};
    p.ambient = 0.0;
    p.diffuse = 0.7;
    p.specular_reflectance = 0.0;
    Light light;
    light.diffuse = glm::vec3(1.0f, 0.5f, 2.0f);
    light.direction = {0, 0, 1};
    const glm::dvec3 n(0, 0, 1), v(0, 0, 1);
    // Facing the light: ward = rho_d*Kd*Id; reversed = w*Id*(Kd/Y)*(1 - Y), Y = Y(Kd).
    const double y = 0.2126 * 0.2 + 0.7152 * 0.5 + 0.0722 * 0.8;
    const auto ward_lit = ward::shade(p, light, ward::Variant::ward, n, v, 1.0);
    const auto rev_lit =
        ward::shade(p, light, ward::Variant::contrast_reversed, n, v, 1.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(ward_lit[c], 0.7 * p.albedo[c] * light.diffuse[c], 1e-6);
        EXPECT_NEAR(rev_lit[c], 0.7 * light.diffuse[c] * p.albedo[c] / y * (1.0 - y),
                    1e-6);
    }
    // In the attached shadow (N.L <= 0) the reversed term is the whole light,
    // w*Id*chroma.
    const glm::dvec3 away(0, 0, -1);
    const auto rev_dark =
        ward::shade(p, light, ward::Variant::contrast_reversed, away, v, 1.0);
    EXPECT_NEAR(rev_dark.b, 0.7 * 2.0 * 0.8 / y, 1e-6);
    EXPECT_EQ(ward::shade(p, light, ward::Variant::ward, away, v, 1.0), glm::dvec3(0.0));
    // Specular at normal incidence: pi * rho_s / (4 pi alpha^2) * Is.
    p.diffuse = 0.0;
    p.specular_reflectance = 0.1;
    p.roughness = 0.2;
    const auto spec = ward::shade(p, light, ward::Variant::ward, n, v, 1.0);
    EXPECT_NEAR(spec.r, 0.1 / (4.0 * 0.04), 1e-5);
}

class WardGlTest : public test::HeadlessGlTest {};

TEST_F(WardGlTest, GlMatchesCpuReferenceOnBuiltinMeshes) {
    gl::FrameExecutor executor;
    for (const char* technique : {"ward", "contrast_reversed"})
        for (const char* mesh : {"sphere:2k", "torus_knot:4k"})
            for (const char* roughness : {"0.08", "0.3"}) {
                const Scene scene = scene_for(technique,
                                              {{"ao_rays", "32"},
                                               {"roughness", roughness},
                                               {"specular_reflectance", "0.2"}},
                                              mesh, 96);
                const Image gl_image = render_image(executor, scene);
                const Image cpu_image = find_technique(technique).render_reference(scene);
                // Mean absolute error and 99th percentile outside a 1-pixel silhouette
                // band.
                const ImageErrorStats c = compare_images(gl_image, cpu_image);
                SCOPED_TRACE(std::string(technique) + " " + mesh + " roughness " +
                             roughness);
                EXPECT_GT(c.pixels, 1000u);
                EXPECT_LT(c.mean, 1.0 / 255.0);
                EXPECT_LT(c.p99, 4.0 / 255.0);
                std::printf("%s %s roughness %s: mean %.2e p99 %.2e over %zu pixels\n",
                            technique, mesh, roughness, c.mean, c.p99, c.pixels);
            }
}

TEST_F(WardGlTest, ComparisonTellsTheTwoVariantsApart) {
    // The same scene under the other variant's reference must fail the thresholds above.
    gl::FrameExecutor executor;
    const Scene ward_scene =
        scene_for("ward", {{"ao_rays", "16"}, {"diffuse_reflectance", "0.5"}});
    const Scene reversed_scene =
        scene_for("contrast_reversed", {{"ao_rays", "16"}, {"reversed_diffuse", "0.5"}});
    const ImageErrorStats c = compare_images(
        render_image(executor, ward_scene),
        find_technique("contrast_reversed").render_reference(reversed_scene));
    EXPECT_GT(c.mean, 10.0 / 255.0);
}

}  // namespace
}  // namespace lucent
