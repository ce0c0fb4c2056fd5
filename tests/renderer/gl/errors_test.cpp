// GL errors are reported, not rendered as black: an invalid upload and an invalid call
// inside a pass throw one-line GlErrors naming what failed, and a debug context adds the
// driver's message for the call.
#include "renderer/gl/errors.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <string>
#include <vector>

#include "renderer/gl/frame_executor.h"
#include "renderer/gl/upload.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "tests/support/gl_test_fixture.h"

namespace lucent {
namespace {

class GlErrors : public test::HeadlessGlTest {};

// The GlError's message, or "" when `f` did not throw one.
template <typename F>
std::string gl_error_of(F&& f) {
    try {
        f();
    } catch (const gl::GlError& e) {
        return e.what();
    }
    return "";
}

TEST_F(GlErrors, UploadOutsideTheTextureIsReportedNamingTheUpload) {
    gl::check_errors("test start");
    const gl::Texture texture = gl::make_texture_2d(GL_RGBA8, 4, 4);
    const std::vector<std::uint8_t> pixels(8 * 8 * 4, 255);
    const std::string message =
        gl_error_of([&] { gl::upload_texture_rgba8(texture, 8, 8, pixels); });
    EXPECT_NE(message.find("GL error in upload of 8x8 RGBA8 pixels: GL_INVALID_VALUE"),
              std::string::npos)
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    // A buffer of the wrong size never reaches GL.
    EXPECT_THROW(gl::upload_texture_rgba8(texture, 4, 4, pixels), std::invalid_argument);
    // The error was consumed: the next check is clean, and a valid upload passes.
    EXPECT_NO_THROW(gl::check_errors("after the failed upload"));
    EXPECT_NO_THROW(
        gl::upload_texture_rgba8(texture, 4, 4, std::vector<std::uint8_t>(4 * 4 * 4, 7)));
}

// A uniform of the wrong type (an int for the vec3 albedo) is GL_INVALID_OPERATION; the
// frame stops at that pass instead of returning an image without the albedo.
TEST_F(GlErrors, InvalidCallInAPassThrowsNamingThePass) {
    RenderRequest request;
    request.mesh = "sphere:2k";
    request.settings = {{"ambient", "0"}, {"backlight", "0"}};
    request.width = request.height = 16;
    const Scene scene = build_scene(request);
    FramePlan plan = make_frame_plan(scene, find_technique("empirical"));
    bool found = false;
    for (Pass& pass : plan.passes)
        if (pass.name == "shade") {
            pass.uniforms.push_back({"u_albedo", 1});
            found = true;
        }
    ASSERT_TRUE(found) << plan.explain();
    gl::FrameExecutor executor;
    const std::string message = gl_error_of([&] { executor.execute(scene, plan); });
    EXPECT_NE(message.find("GL error in pass 'shade': GL_INVALID_OPERATION"),
              std::string::npos)
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    // The same executor renders the untouched plan afterwards.
    EXPECT_NO_THROW(render_image(executor, scene));
}

// Errors left by code outside the executor are not blamed on the frame's first pass.
TEST_F(GlErrors, EarlierErrorsAreNamedAsSuch) {
    glBindTextureUnit(0, 999999);  // no such texture: GL_INVALID_OPERATION
    gl::FrameExecutor executor;
    RenderRequest request;
    request.mesh = "sphere:200";
    request.settings = {{"ambient", "0"}, {"backlight", "0"}};
    request.width = request.height = 8;
    const std::string message =
        gl_error_of([&] { render_image(executor, build_scene(request)); });
    EXPECT_NE(message.find("GL error in GL calls before this frame"), std::string::npos)
        << message;
}

// The session runner renders each live stimulus with its own executor and then draws
// with ImGui, whose back end saves the bound program and restores it: a program the
// executor left bound, then deleted, made that restore GL_INVALID_VALUE.
TEST_F(GlErrors, ExecutorLeavesNoProgramOrVertexArrayBound) {
    RenderRequest request;
    request.mesh = "sphere:200";
    request.settings = {{"ambient", "0"}};
    request.width = request.height = 8;
    const Scene scene = build_scene(request);
    GLint program = -1, vertex_array = -1, framebuffer = -1;
    {
        gl::FrameExecutor executor;
        render_image(executor, scene);
        glGetIntegerv(GL_CURRENT_PROGRAM, &program);
        glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vertex_array);
        glGetIntegerv(GL_FRAMEBUFFER_BINDING, &framebuffer);
    }
    EXPECT_EQ(program, 0);
    EXPECT_EQ(vertex_array, 0);
    EXPECT_EQ(framebuffer, 0);
    glUseProgram(static_cast<GLuint>(program));  // what ImGui's restore does
    EXPECT_NO_THROW(gl::check_errors("restoring the saved program"));
}

// A debug context delivers the driver's message for the failing call.
TEST(GlDebugContext, AddsTheDriversMessageToTheError) {
    gl::ContextOptions options;
    options.debug = true;
    std::unique_ptr<gl::Context> context;
    try {
        context = gl::create_headless_context(options);
    } catch (const gl::ContextError& e) {
        GTEST_SKIP() << "no headless GL context: " << e.what();
    }
    GLint flags = 0;
    glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
    ASSERT_TRUE(flags & GL_CONTEXT_FLAG_DEBUG_BIT);
    const gl::Texture texture = gl::make_texture_2d(GL_RGBA8, 2, 2);
    const std::string message = gl_error_of([&] {
        gl::upload_texture_rgba8(texture, 3, 3, std::vector<std::uint8_t>(3 * 3 * 4));
    });
    // "GL error in upload ...: GL_INVALID_VALUE: <the driver's message>"; Mesa's names
    // the call, other drivers word it their own way.
    const std::string marker = "GL_INVALID_VALUE: ";
    const auto at = message.find(marker);
    ASSERT_NE(at, std::string::npos) << message;
    EXPECT_GT(message.size(), at + marker.size() + 4) << message;
    const std::string renderer = context->info().renderer;
    if (renderer.find("llvmpipe") != std::string::npos) {
        EXPECT_NE(message.find("TextureSubImage2D"), std::string::npos) << message;
    }
}

TEST(GlDebugContext, DefaultInDebugBuildsAndWhereLucentGlDebugIsOne) {
    const char* before = std::getenv("LUCENT_GL_DEBUG");
    const std::string saved = before ? before : "";
    setenv("LUCENT_GL_DEBUG", "1", 1);
    EXPECT_TRUE(gl::ContextOptions{}.debug);
    unsetenv("LUCENT_GL_DEBUG");
#ifdef NDEBUG
    EXPECT_FALSE(gl::ContextOptions{}.debug);
#else
    EXPECT_TRUE(gl::ContextOptions{}.debug);
#endif
    if (before) setenv("LUCENT_GL_DEBUG", saved.c_str(), 1);
}

}  // namespace
}  // namespace lucent
