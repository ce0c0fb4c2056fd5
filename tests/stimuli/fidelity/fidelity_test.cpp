// bench fidelity's parts: the image error against closed forms, the knobs a technique
// takes from the truth by name, and the fit recovering a known appearance (a ward image
// with known values as the "truth": the fit must bring the error near 0 from its
// defaults).
#include "stimuli/fidelity/fidelity.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/scene_for_test.h"

namespace lucent::stimuli {
namespace {

Image flat(int w, int h, glm::vec4 value) {
    Image image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) image.set(x, y, value);
    return image;
}

TEST(Fidelity, ImageErrorIsZeroForTheSameImageAndTheRmsOfAConstantOffset) {
    const Image a = flat(4, 3, {0.2f, 0.4f, 0.6f, 1.0f});
    ImageError e = image_error(a, a);
    EXPECT_EQ(e.pixels, 12u);
    EXPECT_EQ(e.mean_delta_e, 0.0);
    EXPECT_EQ(e.rmse, 0.0);
    const Image b = flat(4, 3, {0.3f, 0.5f, 0.7f, 1.0f});
    e = image_error(b, a);
    EXPECT_NEAR(e.rmse, 0.1, 1e-6);
    EXPECT_GT(e.mean_delta_e, 1.0);
    EXPECT_NEAR(e.p95_delta_e, e.mean_delta_e, 1e-9);  // every pixel differs alike
    // Background in both (alpha 0) is left out, whatever its colour.
    Image c = b;
    c.set(0, 0, {1.0f, 1.0f, 1.0f, 0.0f});
    Image d = a;
    d.set(0, 0, {0.0f, 0.0f, 0.0f, 0.0f});
    EXPECT_EQ(image_error(c, d).pixels, 11u);
    EXPECT_NEAR(image_error(c, d).rmse, 0.1, 1e-6);
    EXPECT_THROW(image_error(flat(2, 2, {}), a), std::invalid_argument);
}

TEST(Fidelity, ATechniqueTakesTheTruthsKnobsOfTheSameName) {
    const Scene truth = test::scene_for("path",
                                        {{"material", "marble"},
                                         {"model_size", "30"},
                                         {"density", "marble"},
                                         {"light_direction", "0.2,0.5,-1"}},
                                        "sphere:2k", 16);
    std::vector<KnobAssignment> taken;
    const Scene dipole = scene_like(truth, find_technique("dipole"), {}, &taken);
    EXPECT_EQ(dipole.values.choice("material"), "marble");
    EXPECT_EQ(dipole.values.scalar("model_size"), 30.0);
    EXPECT_EQ(dipole.light.direction, truth.light.direction);
    EXPECT_EQ(dipole.camera.view(), truth.camera.view());
    const auto named = [&](const std::string& key) {
        return std::any_of(taken.begin(), taken.end(),
                           [&](const KnobAssignment& a) { return a.key == key; });
    };
    EXPECT_TRUE(named("material"));
    EXPECT_FALSE(named("light_radius"));  // the path's own
    const Scene htsm = scene_like(truth, find_technique("htsm"), {});
    ASSERT_TRUE(htsm.density);
    EXPECT_EQ(htsm.density->content_hash, truth.density->content_hash);
}

class FidelityGl : public test::HeadlessGlTest {};

TEST_F(FidelityGl, TheFitRecoversAKnownAppearance) {
    gl::FrameExecutor executor;
    const std::vector<KnobAssignment> scene = {{"light_direction", "0.4,0.6,1"}};
    const Scene truth_scene = test::scene_for("path", scene, "sphere:2k", 32);
    // The "truth": ward with known values, other than its defaults.
    std::vector<KnobAssignment> known = scene;
    known.insert(known.end(), {{"albedo", "0.25,0.5,0.7"},
                               {"diffuse_reflectance", "0.8"},
                               {"roughness", "0.2"},
                               {"specular_reflectance", "0.05"}});
    const Image truth =
        render_image(executor, test::scene_for("ward", known, "sphere:2k", 32));
    FitOptions options;
    options.max_evaluations = 300;
    const TechniqueFit fit =
        fit_to_truth(executor, find_technique("ward"), truth_scene, truth, options);
    ASSERT_TRUE(fit.refused.empty()) << fit.refused;
    EXPECT_GT(fit.start_error.mean_delta_e, 5.0);
    EXPECT_LT(fit.error.mean_delta_e, 0.5) << "after " << fit.evaluations << " renders";
    EXPECT_LE(fit.evaluations, 300);
    EXPECT_FALSE(fit.quality.empty());  // ward's ao_rays sweep
    EXPECT_GT(fit.frame_ms, 0.0);
}

TEST_F(FidelityGl, ATechniqueThatCannotRenderTheMeshIsReportedNotFitted) {
    gl::FrameExecutor executor;
    const Scene truth_scene = test::scene_for("path", {}, "sphere:2k", 8);
    const TechniqueFit fit =
        fit_to_truth(executor, find_technique("thick_texture"), truth_scene, Image(8, 8));
    EXPECT_FALSE(fit.refused.empty());
    EXPECT_EQ(fit.evaluations, 0);
}

}  // namespace
}  // namespace lucent::stimuli
