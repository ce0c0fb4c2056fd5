// The explorer under X (xvfb-run in scripts/test): it starts and renders, scripted UI
// events travel the same input path as real ones and change parameters with the
// expected effect on the image, "Save image" equals `lucent render` bit for bit, and
// "Add to stimulus set" writes a config `lucent render` renders. Without DISPLAY it
// skips by hand and fails under scripts/test (display.h).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

#include "renderer/techniques/registry.h"
#include "stimuli/explorer/explorer.h"
#include "tests/support/display.h"
#include "tests/support/flat_test_technique.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "renderer/core/image.h"
#include "tests/support/test_paths.h"

namespace lucent::explorer {
namespace {

constexpr const char* kMesh = "torus_knot:4k";

class ExplorerTest : public ::testing::Test {
protected:
    void SetUp() override { LUCENT_REQUIRE_DISPLAY(); }

    std::unique_ptr<Explorer> open(ExplorerSession session, int width = 800,
                                   int height = 560) {
        session.mesh = kMesh;
        ExplorerOptions options;
        options.width = width;
        options.height = height;
        return std::make_unique<Explorer>(std::move(session), options);
    }

    // Steps until the shown set has a frame rendered with the current parameters (the
    // first frames may wait for the AO bake).
    static const Image& settle(Explorer& explorer) {
        const auto deadline =
            std::chrono::steady_clock::now() + std::chrono::seconds(120);
        do {
            explorer.step();
        } while ((explorer.ambient_occlusion_pending() || !explorer.shown().valid) &&
                 std::chrono::steady_clock::now() < deadline);
        explorer.step();  // one frame with the bake in place
        EXPECT_TRUE(explorer.shown().valid);
        return explorer.shown().image;
    }

    static void click(Explorer& explorer, float x, float y) {
        InputRouter& input = explorer.input();
        input.enqueue(MouseMove{x, y});
        input.enqueue(WaitFrames{1});
        input.enqueue(MouseButton{0, true});
        input.enqueue(WaitFrames{1});
        input.enqueue(MouseButton{0, false});
        input.enqueue(WaitFrames{1});
        while (!input.script_done()) explorer.step();
    }
};

int run(const std::string& command) {
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string render_command(const RenderRequest& request, const std::string& out) {
    std::ostringstream command;
    command << LUCENT_EXECUTABLE << " render --mesh " << request.mesh << " --technique "
            << request.technique << " --size " << request.width << "x" << request.height
            << " --out " << out;
    for (const auto& s : request.settings) command << " --set " << s.key << "=" << s.text;
    return command.str() + " > /dev/null";
}

std::size_t covered_pixels(const Image& image) {
    std::size_t n = 0;
    for (std::size_t i = 3; i < image.rgba.size(); i += 4) n += image.rgba[i] > 0.5f;
    return n;
}

TEST_F(ExplorerTest, StartsRendersFramesAndSavesAScreenshot) {
    auto explorer = open(ExplorerSession{});
    const Image& image = settle(*explorer);
    int width = 0, height = 0;
    explorer->view_size(width, height);
    EXPECT_EQ(image.width, width);
    EXPECT_EQ(image.height, height);
    const std::size_t covered = covered_pixels(image);
    EXPECT_GT(covered,
              image.rgba.size() / 4 / 20);      // the knot fills a good part of the view
    EXPECT_LT(covered, image.rgba.size() / 4);  // and background remains
    EXPECT_GT(explorer->frame_times().frames, 0);
    EXPECT_FALSE(explorer->shown().plan.passes.empty());

    const auto path =
        test::binary_dir() / "test-output" / "explorer" / "explorer_window.png";
    std::filesystem::create_directories(path.parent_path());
    explorer->session().show_axes = explorer->session().show_bounds = true;
    explorer->request_screenshot(path);
    explorer->step();
    const Image shot = read_image(path);
    EXPECT_EQ(shot.width, 800);
    EXPECT_EQ(shot.height, 560);
    std::cout << "explorer screenshot: " << path.string() << "\n";
}

// Eq. 3.6 is linear in the backlight weight wb: I(wb) = I(0) + wb * T with T >= 0 the
// thickness term, largest where the object is thinnest. A click on the backlight slider
// (scripted through the input router) must move the image exactly along that line.
TEST_F(ExplorerTest, ScriptedSliderClickRaisesBacklightAndBrightensThinParts) {
    ExplorerSession session;
    session.current().set("backlight", 0.0);
    auto explorer = open(session);
    const Image unlit = settle(*explorer);
    explorer->session().current().set("backlight", 0.5);
    const Image half = settle(*explorer);

    const auto slider = explorer->widget("backlight");
    ASSERT_TRUE(slider) << "backlight slider not drawn";
    click(*explorer, 0.5f * (slider->x0 + slider->x1), 0.5f * (slider->y0 + slider->y1));
    const double wb = explorer->session().current().values().scalar("backlight");
    EXPECT_NEAR(wb, 5.0, 0.3);  // the middle of its documented range [0, 10]
    const Image raised = settle(*explorer);

    ASSERT_EQ(raised.rgba.size(), half.rgba.size());
    double gain_sum = 0.0;
    std::size_t brighter = 0;
    for (std::size_t i = 0; i < raised.rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        const double thickness_term = (half.rgba[i] - unlit.rgba[i]) / 0.5;  // T
        const double expected = unlit.rgba[i] + wb * thickness_term;
        ASSERT_NEAR(raised.rgba[i], expected, 1e-4 + 1e-4 * std::abs(expected))
            << "value " << i;
        EXPECT_GE(thickness_term, -1e-5);
        brighter += raised.rgba[i] > half.rgba[i] + 1e-3f;
        gain_sum += raised.rgba[i] - half.rgba[i];
    }
    EXPECT_GT(brighter, covered_pixels(raised) / 10);
    EXPECT_GT(gain_sum, 0.0);
}

// With pass times on, a frame with nothing changed re-runs no pass and a slider re-runs
// only the passes it touches; the other passes show as cached.
TEST_F(ExplorerTest, SlidersRerunOnlyThePassesTheyTouch) {
    ExplorerSession session;
    session.show_pass_times = true;
    auto explorer = open(session);
    const Image before = settle(*explorer);
    explorer->step();
    const auto ran = [&] {
        std::vector<std::string> names;
        for (const auto& t : explorer->shown().timings.passes)
            if (!t.cached) names.push_back(t.pass);
        return names;
    };
    EXPECT_FALSE(explorer->shown().timings.passes.empty());
    EXPECT_EQ(ran(), std::vector<std::string>{});
    explorer->session().current().set("shininess", 40.0);
    explorer->step();
    EXPECT_EQ(ran(), std::vector<std::string>{"shade"});
    EXPECT_NE(explorer->shown().image.rgba, before.rgba);  // the highlight did change
    explorer->step();
    EXPECT_EQ(ran(), std::vector<std::string>{});
}

// A frame in which no pass re-ran (pass reuse) shows the image it already has: no
// read-back, encoding or upload (most of an idle frame at 1280x720); a slider reads the
// new image back once.
TEST_F(ExplorerTest, IdleFramesReadNothingBack) {
    ExplorerSession session;  // pass times off: reuse is reported all the same
    auto explorer = open(session);
    const Image before = settle(*explorer);
    const std::size_t reads = explorer->shown().read_backs;
    ASSERT_GT(reads, 0u);
    explorer->step();
    explorer->step();
    EXPECT_EQ(explorer->shown().read_backs, reads);
    EXPECT_EQ(explorer->shown().image.rgba, before.rgba);
    explorer->session().current().set("shininess", 40.0);
    explorer->step();
    EXPECT_EQ(explorer->shown().read_backs, reads + 1);
    EXPECT_NE(explorer->shown().image.rgba, before.rgba);
    explorer->step();
    EXPECT_EQ(explorer->shown().read_backs, reads + 1);
}

// The dipole refines progressively (4 samples a frame, core/progressive.h): the status
// counts up to the set's N, then frames run no pass; a slider restarts the refinement.
TEST_F(ExplorerTest, TheDipoleRefinesOverFramesToTheSetsSamples) {
    ExplorerSession session;
    session.show_pass_times = true;
    session.sets[0].set_technique("dipole");
    session.sets[0].set("samples", 12);
    session.sets[0].set("atlas_resolution", std::string("256"));
    session.sets[0].set("light_map_resolution", std::string("256"));
    auto explorer = open(session, 320, 240);
    settle(*explorer);
    // settle() stepped until the first frame, then once more: 8 of 12 samples.
    EXPECT_EQ(explorer->shown().refinement_status(), "refining: 8 of 12 samples");
    explorer->step();
    EXPECT_EQ(explorer->shown().refinement_status(), "");
    ASSERT_TRUE(explorer->shown().refinement.has_value());
    EXPECT_EQ(explorer->shown().refinement->samples(), 12);
    const Image converged = explorer->shown().image;
    explorer->step();  // nothing left to refine: the same image
    EXPECT_EQ(explorer->shown().image.rgba, converged.rgba);
    explorer->session().current().set("specular", 0.0);
    explorer->step();
    EXPECT_EQ(explorer->shown().refinement_status(), "refining: 4 of 12 samples");
    EXPECT_NE(explorer->shown().image.rgba, converged.rgba);
}

// The path tracer refines the same way, one path per pixel and channel a frame, each
// frame's trace a background bake (the view keeps its last complete frame meanwhile and
// asks for the same seed again until the bake is in): it reaches the set's paths.
TEST_F(ExplorerTest, ThePathTracerRefinesOverFramesToTheSetsPaths) {
    ExplorerSession session;
    session.sets[0].set_technique("path");
    session.sets[0].set("paths", 3);
    session.sets[0].set("material", std::string("marble"));
    auto explorer = open(session, 200, 150);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
    const auto converged = [&] {
        const RenderedSide& side = explorer->shown();
        return side.valid && side.refinement && side.refinement->converged();
    };
    while (!converged() && std::chrono::steady_clock::now() < deadline) explorer->step();
    ASSERT_TRUE(converged());
    EXPECT_EQ(explorer->shown().refinement->samples(), 3);
    EXPECT_EQ(explorer->shown().refinement->frames(), 3);
    EXPECT_GT(covered_pixels(explorer->shown().image), 100u);
    for (const float v : explorer->shown().image.rgba) ASSERT_TRUE(std::isfinite(v));
}

TEST_F(ExplorerTest, DragsOnTheViewOrbitAndMoveTheLight) {
    auto explorer = open(ExplorerSession{});
    settle(*explorer);
    const glm::dvec3 light =
        explorer->session().current().values().vec3("light_direction");
    InputRouter& input = explorer->input();
    // Right-drag to the right in the view (right of the panel): the light turns to +x.
    input.enqueue(MouseMove{700.f, 200.f});
    input.enqueue(MouseButton{1, true});
    input.enqueue(MouseMove{740.f, 200.f});
    input.enqueue(MouseButton{1, false});
    // Left-drag to the left: orbit.
    input.enqueue(MouseMove{700.f, 300.f});
    input.enqueue(MouseButton{0, true});
    input.enqueue(MouseMove{650.f, 300.f});
    input.enqueue(MouseButton{0, false});
    while (!input.script_done()) explorer->step();
    const glm::dvec3 moved =
        explorer->session().current().values().vec3("light_direction");
    EXPECT_GT(moved.x / glm::length(moved), light.x / glm::length(light) + 0.05);
    EXPECT_NEAR(explorer->session().yaw_degrees, 20.f, 1e-3f);  // 50 px at 0.4 deg/px
}

// A/B: side by side renders both sets at half width each; the space bar (a key event
// through the router) flips which set the panels edit.
TEST_F(ExplorerTest, SideBySideShowsBothSetsAndSpaceFlips) {
    ExplorerSession session;
    session.sets[1].set("backlight", 0.0);
    session.side_by_side = true;
    auto explorer = open(session);
    settle(*explorer);
    const RenderedSide &a = explorer->side(0), &b = explorer->side(1);
    ASSERT_TRUE(a.valid && b.valid);
    EXPECT_EQ(a.image.width, 400);
    EXPECT_EQ(b.image.width, 400);
    double sum_a = 0.0, sum_b = 0.0;  // B lacks the backlight term, which only adds light
    for (std::size_t i = 0; i < a.image.rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        sum_a += a.image.rgba[i];
        sum_b += b.image.rgba[i];
    }
    EXPECT_GT(sum_a, sum_b);
    EXPECT_EQ(explorer->session().edited, 0);
    explorer->input().enqueue(MouseMove{700.f, 100.f});  // over the view, not a panel
    explorer->input().enqueue(Key{GLFW_KEY_SPACE, true});
    explorer->input().enqueue(Key{GLFW_KEY_SPACE, false});
    while (!explorer->input().script_done()) explorer->step();
    EXPECT_EQ(explorer->session().edited, 1);
}

TEST_F(ExplorerTest, SaveImageEqualsLucentRender) {
    ExplorerSession session;
    session.current().apply({{"backlight", "1.6"},
                             {"thickness_exponent", "18"},
                             {"albedo", "0.5,0.6,0.7"},
                             {"blur_kernel", "3"}});
    auto explorer = open(session, 520, 400);
    settle(*explorer);
    const auto dir = test::scratch_dir("explorer_save");
    explorer->save_image(dir / "explorer.exr");
    int width = 0, height = 0;
    explorer->view_size(width, height);
    const RenderRequest request =
        render_request(explorer->session(), explorer->session().edited, width, height);
    ASSERT_EQ(run(render_command(request, (dir / "render.exr").string())), 0);
    const Image saved = read_image(dir / "explorer.exr"),
                rendered = read_image(dir / "render.exr");
    ASSERT_EQ(saved.width, rendered.width);
    ASSERT_EQ(saved.height, rendered.height);
    float max_diff = 0.f;
    for (std::size_t i = 0; i < saved.rgba.size(); ++i)
        max_diff = std::max(max_diff, std::abs(saved.rgba[i] - rendered.rgba[i]));
    EXPECT_EQ(max_diff, 0.f);
    EXPECT_GT(covered_pixels(saved), 0u);
}

// Developer mode: shaders are read again from LUCENT_SHADER_DIR. A shade.frag that ends
// by writing a fixed colour must show that colour on every covered pixel after reload.
TEST_F(ExplorerTest, ReloadShadersReadsEditedShadersFromDisk) {
    auto explorer = open(ExplorerSession{});
    const Image before = settle(*explorer);
    const auto dir = test::scratch_dir("explorer_shaders");
    const std::string relative = "techniques/empirical/shaders/shade.frag";
    std::ifstream in(test::source_dir() / "renderer" / relative);
    std::stringstream text;
    text << in.rdbuf();
    std::string source = text.str();
    source.insert(source.rfind('}'), "    out_colour = vec4(0.25, 0.5, 0.75, 1.0);\n");
    std::filesystem::create_directories((dir / relative).parent_path());
    std::ofstream(dir / relative) << source;

    setenv("LUCENT_SHADER_DIR", dir.c_str(), 1);
    explorer->reload_shaders();
    const Image edited = settle(*explorer);
    unsetenv("LUCENT_SHADER_DIR");
    ASSERT_GT(covered_pixels(edited), 0u);
    for (std::size_t i = 0; i < edited.rgba.size(); i += 4) {
        if (edited.rgba[i + 3] < 1.f) continue;
        ASSERT_EQ(edited.rgba[i], 0.25f);
        ASSERT_EQ(edited.rgba[i + 1], 0.5f);
        ASSERT_EQ(edited.rgba[i + 2], 0.75f);
    }
    explorer->reload_shaders();  // back to the embedded shaders
    const Image restored = settle(*explorer);
    unsetenv("LUCENT_SHADER_DIR");  // reload_shaders() pointed it at the source tree
    EXPECT_EQ(restored.rgba, before.rgba);
}

TEST_F(ExplorerTest, AddToStimulusSetButtonWritesAConfigLucentRenderRenders) {
    const auto dir = test::scratch_dir("explorer_add");
    const auto config = dir / "set.toml";
    std::ofstream(config)
        << "# kept comment\nname = \"t\"\nresolution = [64, 48]\nformats = [\"exr\"]\n"
           "[meshes]\nknot = \""
        << kMesh
        << "\"\n[[stimuli]]\nid = \"base\"\n"
           "technique = \"ward\"\n";
    ExplorerSession session;
    session.stimulus_config = config.string();
    session.stimulus_id = "from_explorer";
    session.current().apply({{"thickness_exponent", "12"}});
    auto explorer = open(session);
    settle(*explorer);
    const auto button = explorer->widget("Add to stimulus set");
    ASSERT_TRUE(button) << "button not drawn";
    click(*explorer, 0.5f * (button->x0 + button->x1), 0.5f * (button->y0 + button->y1));
    EXPECT_NE(explorer->session().message.find("from_explorer"), std::string::npos)
        << explorer->session().message;

    ASSERT_EQ(run(std::string(LUCENT_EXECUTABLE) + " render " + config.string() +
                  " --out " + (dir / "out").string() + " > /dev/null 2>&1"),
              0);
    ASSERT_TRUE(std::filesystem::exists(dir / "out" / "from_explorer.exr"));
    // The set's stimulus is the explorer's parameters at the set's size: `lucent render
    // --mesh` with the same request gives the same pixels.
    const RenderRequest request =
        render_request(explorer->session(), explorer->session().edited, 64, 48);
    ASSERT_EQ(run(render_command(request, (dir / "single.exr").string())), 0);
    const Image a = read_image(dir / "out" / "from_explorer.exr"),
                b = read_image(dir / "single.exr");
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    for (std::size_t i = 0; i < a.rgba.size(); ++i) ASSERT_EQ(a.rgba[i], b.rgba[i]) << i;
}

// A technique that exists only in this test, registered here, is seen by the explorer:
// it can be chosen, its own panel is drawn with its knob and suggested values, and the
// view shows its picture (issue 27 item 2).
TEST_F(ExplorerTest, ATechniqueRegisteredByATestGetsItsPanelsAndItsPicture) {
    const test::FlatTestTechnique flat;
    const TechniqueRegistration registration(flat);
    ExplorerSession session;
    session.current().set_technique(test::FlatTestTechnique::kName);
    session.current().set("levels", 5);
    auto explorer = open(session);
    const Image& shown = settle(*explorer);
    EXPECT_TRUE(explorer->widget("flat_colour")) << "its knob in its own panel";
    EXPECT_TRUE(explorer->widget("levels")) << "its quality knob with the technique's";
    EXPECT_TRUE(explorer->widget("0.25")) << "a suggested value's button";
    ASSERT_GT(shown.width, 0);
    const glm::vec4 centre = shown.at(shown.width / 2, shown.height / 2);
    EXPECT_FLOAT_EQ(centre.r, test::FlatTestTechnique::quantised(0.3, 5));
    EXPECT_FLOAT_EQ(centre.b, test::FlatTestTechnique::quantised(0.7, 5));
}

}  // namespace
}  // namespace lucent::explorer
