// contrast_reversed (Domon et al. Eq. 15): luminance reversal that keeps the albedo's
// hue, no negative values, a black background, and pruned plans equal to full ones.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/core/technique.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "renderer/techniques/ward/ward.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/scene_for_test.h"

namespace lucent {
namespace {

Scene scene_for(const std::string& technique, std::vector<KnobAssignment> settings,
                const std::string& mesh = "sphere:2k", int size = 64) {
    return test::scene_for(technique, std::move(settings), mesh, size);
}

TEST(ContrastReversedShading, ReversesLuminanceAndKeepsHue) {
    ward::Params p;
    p.albedo = {0.2, 0.5, 0.8};
    p.ambient = 0.0;
    p.diffuse = 0.7;
    p.specular_reflectance = 0.0;
    Light light;
    light.direction = {0, 0, 1};
    const glm::dvec3 n(0, 0, 1), v(0, 0, 1);
    const double y = 0.2126 * 0.2 + 0.7152 * 0.5 + 0.0722 * 0.8;
    // Luminance, not channels, is reversed: under white light the term keeps Kd's hue
    // (channel ratios) and its luminance is w * (1 - Y N.L), Eq. 12 with Li = 1.
    light.diffuse = glm::vec3(1.0f);
    const auto tilted = ward::shade(p, light, ward::Variant::contrast_reversed,
                                    glm::normalize(glm::dvec3(0, 0.6, 0.8)), v, 1.0);
    EXPECT_NEAR(tilted.b / tilted.r, 0.8 / 0.2, 1e-9);
    EXPECT_NEAR(0.2126 * tilted.r + 0.7152 * tilted.g + 0.0722 * tilted.b,
                0.7 * (1.0 - y * 0.8), 1e-9);
    // A white albedo facing the light reverses to exactly 0, never negative; a black one
    // has no hue to keep and reverses to the light's colour.
    p.albedo = glm::dvec3(1.0);
    EXPECT_EQ(ward::shade(p, light, ward::Variant::contrast_reversed, n, v, 1.0),
              glm::dvec3(0.0));
    p.albedo = glm::dvec3(0.0);
    const auto black = ward::shade(p, light, ward::Variant::contrast_reversed, n, v, 1.0);
    EXPECT_NEAR(black.g, 0.7, 1e-12);
    EXPECT_TRUE(std::isfinite(black.r));
}

class ContrastReversedGlTest : public test::HeadlessGlTest {};

TEST_F(ContrastReversedGlTest, KeepsABlackBackgroundAndFiniteValues) {
    gl::FrameExecutor executor;
    const Scene scene =
        scene_for("contrast_reversed",
                  {{"ao_rays", "16"}, {"roughness", "0"}, {"specular_reflectance", "1"}},
                  "torus:2k", 64);
    const Image image = render_image(executor, scene);
    std::size_t background = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const glm::vec4 p = image.at(x, y);
            for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(p[c]));
            for (int c = 0; c < 3; ++c) ASSERT_GE(p[c], 0.0f);
            if (p.a == 0.0f) {
                ++background;
                EXPECT_EQ(glm::vec3(p), glm::vec3(0.0f));
            }
        }
    EXPECT_GT(background, 100u);
}

TEST_F(ContrastReversedGlTest, PrunedPlanEqualsFullPlan) {
    // Each prunable term off (AO bake, specular lobe, diffuse term): the pruned render
    // must equal the render with every pass and term compiled in.
    gl::FrameExecutor executor;
    for (const char* technique : {"ward", "contrast_reversed"}) {
        const std::string diffuse =
            std::string(technique) == "ward" ? "diffuse_reflectance" : "reversed_diffuse";
        for (const KnobAssignment& off :
             {KnobAssignment{"ambient", "0"}, KnobAssignment{"specular_reflectance", "0"},
              KnobAssignment{diffuse, "0"}}) {
            const Scene scene = scene_for(technique, {{"ao_rays", "8"}, off}, "torus:2k");
            const Image pruned = render_image(executor, scene);
            const Image full = render_image(executor, scene, PlanMode::full);
            double max_difference = 0.0;
            for (std::size_t i = 0; i < pruned.rgba.size(); ++i)
                max_difference = std::max(
                    max_difference, double(std::abs(pruned.rgba[i] - full.rgba[i])));
            EXPECT_LT(max_difference, 1e-6) << technique << " " << off.key;
        }
    }
}

}  // namespace
}  // namespace lucent
