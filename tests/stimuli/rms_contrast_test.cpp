// Domon et al. Sec. 6 / Motoyoshi: the contrast-reversed render has lower RMS contrast
// (a narrower luminance histogram) than the ward render with the same parameters.
#include <gtest/gtest.h>

#include "renderer/render.h"
#include "stimuli/image_statistics.h"
#include "tests/support/gl_test_fixture.h"
#include "tests/support/scene_for_test.h"

namespace lucent::stimuli {
namespace {

class RmsContrastTest : public test::HeadlessGlTest {};

ImageStatistics statistics_of(gl::FrameExecutor& executor, const std::string& mesh,
                              const std::string& technique,
                              std::vector<KnobAssignment> settings) {
    const Image image = render_image(
        executor, test::scene_for(technique, std::move(settings), mesh, 128));
    return compute_image_statistics(
        FloatImageView{image.width, image.height, 4, image.rgba});
}

TEST_F(RmsContrastTest, ContrastReversedIsLowerThanWardOnBuiltinMeshes) {
    gl::FrameExecutor executor;
    // The preset's jade / wax / strong materials, and a grey one, under the default light
    // and a side light.
    struct Material {
        const char* albedo;
        const char* weight;
        const char* roughness;
    };
    const Material materials[] = {{"0.45,0.65,0.5", "0.5", "0.08"},
                                  {"0.45,0.65,0.5", "0.5", "0.3"},
                                  {"0.45,0.65,0.5", "0.9", "0.08"},
                                  {"0.5", "0.7", "0.2"}};
    for (const char* mesh : {"sphere:2k", "torus:2k", "torus_knot:4k", "hand:4k"})
        for (const char* light : {"0.4,0.6,1", "1,0.2,0.3"})
            for (const auto& m : materials) {
                std::vector<KnobAssignment> shared = {{"albedo", m.albedo},
                                                      {"roughness", m.roughness},
                                                      {"specular_reflectance", "0.08"},
                                                      {"ambient", "0.15"},
                                                      {"ao_rays", "16"},
                                                      {"light_direction", light}};
                auto ward = shared, reversed = shared;
                ward.push_back({"diffuse_reflectance", m.weight});
                reversed.push_back({"reversed_diffuse", m.weight});
                const auto w = statistics_of(executor, mesh, "ward", ward);
                const auto r =
                    statistics_of(executor, mesh, "contrast_reversed", reversed);
                SCOPED_TRACE(std::string(mesh) + " light " + light + " albedo " +
                             m.albedo + " w " + m.weight + " alpha " + m.roughness);
                EXPECT_EQ(w.object_pixels, r.object_pixels);  // same silhouette
                EXPECT_GT(w.object_pixels, 1000u);
                EXPECT_LT(r.rms_contrast, w.rms_contrast);
            }
}

}  // namespace
}  // namespace lucent::stimuli
