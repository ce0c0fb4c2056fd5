#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "renderer/gl/context.h"
#include "renderer/gl/objects.h"
#include "renderer/gl/program.h"
#include "renderer/gl/readback.h"
#include "tests/support/gl_test_fixture.h"

namespace lucent {
namespace {

using test::HeadlessGlTest;

TEST_F(HeadlessGlTest, ReportsCoreProfile45OrLater) {
    const gl::GlInfo info = context().info();
    EXPECT_FALSE(info.renderer.empty());
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    EXPECT_GE(major * 10 + minor, 45);
    EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
    EXPECT_GE(info.max_texture_size, 4096);
    EXPECT_EQ(context().provider(), "egl");
}

// Draws one triangle with a known colour into an 8x8 RGBA8 framebuffer and checks every
// pixel: inside the triangle x + y < 0.1 (NDC) the colour, elsewhere the clear colour.
// The edge passes between pixel centres, so no rasterisation tie-break decides a pixel.
TEST_F(HeadlessGlTest, DrawsKnownTriangleIntoFramebuffer) {
    constexpr int kSize = 8;
    gl::Texture colour = gl::make_texture_2d(GL_RGBA8, kSize, kSize);
    gl::Framebuffer fbo = gl::make_framebuffer({&colour});

    const char* vertex_src = R"(#version 450 core
        const vec2 kCorners[3] = vec2[](vec2(-1.0, -1.0), vec2(1.1, -1.0), vec2(-1.0, 1.1));
        void main() { gl_Position = vec4(kCorners[gl_VertexID], 0.0, 1.0); })";
    const char* fragment_src = R"(#version 450 core
        out vec4 colour;
        void main() { colour = vec4(1.0, 51.0 / 255.0, 0.0, 1.0); })";
    gl::Program program =
        gl::link_program({{GL_VERTEX_SHADER, "triangle.vert", vertex_src},
                          {GL_FRAGMENT_SHADER, "triangle.frag", fragment_src}});
    gl::VertexArray vao = gl::make_vertex_array();

    glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
    glViewport(0, 0, kSize, kSize);
    const float clear[4] = {0.0f, 0.0f, 1.0f, 1.0f};
    glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, clear);
    glUseProgram(program.id());
    glBindVertexArray(vao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo.id());
    const auto pixels = gl::read_framebuffer_rgba8(kSize, kSize);
    ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

    int inside_count = 0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const std::uint8_t* p = &pixels[(y * kSize + x) * 4];
            const bool inside = x + y <= 7;  // centre NDC sum (x+y+1)/4 - 2 < 0.1
            inside_count += inside;
            if (inside) {
                EXPECT_EQ(p[0], 255) << x << "," << y;
                EXPECT_EQ(p[1], 51) << x << "," << y;
                EXPECT_EQ(p[2], 0) << x << "," << y;
            } else {
                EXPECT_EQ(p[0], 0) << x << "," << y;
                EXPECT_EQ(p[1], 0) << x << "," << y;
                EXPECT_EQ(p[2], 255) << x << "," << y;
            }
            EXPECT_EQ(p[3], 255);
        }
    }
    EXPECT_EQ(inside_count, 36);
}

TEST_F(HeadlessGlTest, ShaderCompileErrorNamesTheSource) {
    try {
        gl::link_program({{GL_FRAGMENT_SHADER, "broken.frag",
                           "#version 450 core\nvoid main() { undeclared = 1.0; }\n"}});
        FAIL() << "expected ShaderError";
    } catch (const gl::ShaderError& e) {
        EXPECT_NE(std::string(e.what()).find("broken.frag"), std::string::npos)
            << e.what();
    }
}

TEST_F(HeadlessGlTest, EmbeddedShaderIsFoundAndDefinesAreInserted) {
    const gl::ShaderStage stage = gl::shader_stage(
        GL_VERTEX_SHADER, "gl/shaders/fullscreen.vert", {"LUCENT_TEST 1"});
    EXPECT_EQ(
        stage.source.rfind("#version 450 core\n#define LUCENT_TEST 1\n#line 2\n", 0), 0u);
    EXPECT_THROW(gl::shader_source("no/such/shader.frag"), gl::ShaderError);
}

// Asking for an OpenGL version that does not exist must fail with a one-line error that
// names the platform, not crash or hand back a context.
TEST(HeadlessContextFailure, ImpossibleVersionReportsPlatformAndReason) {
    gl::ContextOptions options;
    options.gl_major = 9;
    options.gl_minor = 9;
    try {
        auto context = gl::create_headless_context(options);
        FAIL() << "a 9.9 context was created";
    } catch (const gl::ContextError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("EGL"), std::string::npos) << message;
        EXPECT_NE(message.find("9.9"), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

TEST(ContextProviders, UnknownNameListsValidProviders) {
    try {
        gl::create_context("vulkan");
        FAIL();
    } catch (const gl::ContextError& e) {
        EXPECT_NE(std::string(e.what()).find("egl, glfw"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace lucent
