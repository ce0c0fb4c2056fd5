// The live knob renderer of adjust and staircase trials (issue 31): a match re-rendered
// with one knob moved, through one executor with pass reuse, gives the pixels a fresh
// full render of the stimulus with that parameter gives (pruned == full), and re-runs
// only the passes the knob touches.
#include "study/session/live_knob.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "renderer/render.h"
#include "tests/support/gl_test_fixture.h"

namespace lucent::study {
namespace {

class LiveKnob : public test::HeadlessGlTest {};

Scene scene_with(const std::string& exponent) {
    RenderRequest request;
    request.mesh = "sphere:2k";
    request.technique = "empirical";
    request.settings = {{"thickness_exponent", exponent}, {"backlight", "0.6"}};
    request.width = 64;
    request.height = 64;
    return build_scene(request);
}

// A fresh executor's full (unpruned) render of the stimulus with the parameter at v.
Image fresh_full(const std::string& exponent, int width, int height) {
    Scene scene = scene_with(exponent);
    fit_scene_camera(scene, width, height);
    gl::FrameExecutor executor;
    const RenderedImage r = render_image_counted(executor, scene, PlanMode::full);
    EXPECT_EQ(r.non_finite_pixels, 0u);
    return r.image;
}

int ran(const gl::FrameTimings& timings) {
    int n = 0;
    for (const gl::PassTiming& p : timings.passes) n += p.cached ? 0 : 1;
    return n;
}

TEST_F(LiveKnob, AKnobStepReRunsFewerPassesAndGivesTheFreshFullRendersPixels) {
    // Resolved at one size and shown at another, as the session does.
    LiveKnobRenderer live("stimulus 'match'", scene_with("1"), "thickness_exponent", 48,
                          40);
    const Image first = live.render_image(0.8, /*time_passes=*/true);
    const int all = static_cast<int>(live.last_timings().passes.size());
    ASSERT_GT(all, 1);
    EXPECT_EQ(ran(live.last_timings()), all);  // the first frame runs every pass
    EXPECT_EQ(first.rgba, fresh_full("0.8", 48, 40).rgba);

    for (const double v : {2.0, 0.35, 2.0}) {
        SCOPED_TRACE(v);
        const Image stepped = live.render_image(v, true);
        EXPECT_LT(ran(live.last_timings()), all);  // only what the knob touches
        EXPECT_GE(ran(live.last_timings()), 1);
        EXPECT_EQ(stepped.rgba, fresh_full(v == 2.0 ? "2" : "0.35", 48, 40).rgba);
        EXPECT_NE(stepped.rgba, first.rgba);
    }
    // The same value again: nothing re-runs.
    live.render_image(2.0, true);
    EXPECT_EQ(ran(live.last_timings()), 0);
}

TEST_F(LiveKnob, TheTextureIsRefilledInPlaceAndHoldsTheEncodedPicture) {
    LiveKnobRenderer live("stimulus 'match'", scene_with("1"), "thickness_exponent", 32,
                          32);
    const GLuint id = live.render(0.5).texture.id();
    ASSERT_NE(id, 0u);
    const StimulusTexture& t = live.render(3.0);
    EXPECT_EQ(t.texture.id(), id);
    EXPECT_EQ(t.width, 32);
    std::vector<uint8_t> pixels(32 * 32 * 4);
    glGetTextureImage(id, 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(pixels.size()),
                      pixels.data());
    const CpuImage expected = encode_stimulus(fresh_full("3", 32, 32));
    EXPECT_EQ(pixels, expected.rgba);
}

TEST_F(LiveKnob, AValueOutsideTheKnobsRangeOrAnUnknownKnobIsRefusedInOneLine) {
    LiveKnobRenderer live("stimulus 'match'", scene_with("1"), "thickness_exponent", 16,
                          16);
    try {
        live.render_image(-1.0);
        FAIL() << "no refusal";
    } catch (const StimulusError& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("stimulus 'match'"), std::string::npos);
    }
    EXPECT_THROW(
        LiveKnobRenderer("stimulus 'match'", scene_with("1"), "no_such_knob", 16, 16),
        StimulusError);
}

}  // namespace
}  // namespace lucent::study
